# SPDX-License-Identifier: Apache-2.0
# cambium_write_package_files(): writes ${CMAKE_BINARY_DIR}/package-files.txt, every file
# outside the tree that the build takes from the system, one "<who>\t<path>\t<used|defined>" a line:
# the tools, the CMake files of each package found, and every file named by an imported
# target (libraries, include folders, and the files Debian's *Targets.cmake insist on, such
# as OpenImageIO's /usr/bin/iconvert). scripts/check-packages.sh (a ctest) finds the Debian
# package of each and fails unless scripts/setup.sh installs it.

# Imported targets that a package defines but Cambium never uses, whose files live in a
# Debian package we do not install: Imath's Python binding (python3-imath, which would pull
# in numpy and Boost.Python).
set(CAMBIUM_UNUSED_IMPORTED_TARGETS "^Imath::PyImath")

# The targets of `dir` and the folders below it: `property` is IMPORTED_TARGETS (those the
# packages found there define) or BUILDSYSTEM_TARGETS (the project's own).
function(_cambium_directory_targets dir property out)
  get_property(targets DIRECTORY "${dir}" PROPERTY ${property})
  get_property(subdirs DIRECTORY "${dir}" PROPERTY SUBDIRECTORIES)
  foreach(sub IN LISTS subdirs)
    _cambium_directory_targets("${sub}" ${property} more)
    list(APPEND targets ${more})
  endforeach()
  set(${out} ${targets} PARENT_SCOPE)
endfunction()

# The imported targets the project links, directly or through other targets.
function(_cambium_linked_targets out)
  _cambium_directory_targets("${PROJECT_SOURCE_DIR}" BUILDSYSTEM_TARGETS queue)
  set(seen "")
  list(LENGTH queue left)
  while(left GREATER 0)
    list(POP_FRONT queue target)
    list(LENGTH queue left)
    if(target IN_LIST seen OR NOT TARGET "${target}")
      continue()
    endif()
    list(APPEND seen "${target}")
    get_target_property(aliased "${target}" ALIASED_TARGET)
    if(aliased)
      list(APPEND queue "${aliased}")
    endif()
    foreach(prop LINK_LIBRARIES INTERFACE_LINK_LIBRARIES)
      get_target_property(libs "${target}" ${prop})
      if(NOT libs)
        continue()
      endif()
      foreach(lib IN LISTS libs)
        string(REGEX REPLACE "^\\$<(LINK_ONLY|TARGET_NAME_IF_EXISTS):(.*)>$" "\\2" lib "${lib}")
        list(APPEND queue "${lib}")
      endforeach()
      list(LENGTH queue left)
    endforeach()
  endwhile()
  set(linked "")
  foreach(target IN LISTS seen)
    get_target_property(imported "${target}" IMPORTED)
    if(imported)
      list(APPEND linked "${target}")
    endif()
  endforeach()
  set(${out} ${linked} PARENT_SCOPE)
endfunction()

# The absolute paths an imported target names (generator expressions and target names left out).
function(_cambium_target_files target out)
  set(props IMPORTED_LOCATION IMPORTED_IMPLIB INTERFACE_INCLUDE_DIRECTORIES
            INTERFACE_LINK_LIBRARIES)
  get_target_property(configs ${target} IMPORTED_CONFIGURATIONS)
  foreach(config IN LISTS configs)
    list(APPEND props IMPORTED_LOCATION_${config} IMPORTED_IMPLIB_${config})
  endforeach()
  set(files "")
  foreach(prop IN LISTS props)
    get_target_property(values ${target} ${prop})
    foreach(value IN LISTS values)
      if(IS_ABSOLUTE "${value}" AND NOT value MATCHES "\\$<")
        list(APPEND files "${value}")
      endif()
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES files)
  set(${out} ${files} PARENT_SCOPE)
endfunction()

function(cambium_write_package_files)
  find_program(CAMBIUM_PREPROCESSOR cpp DOC "the C preprocessor cambium runs on .l files")
  set(text "")
  foreach(tool CMAKE_CXX_COMPILER CMAKE_MAKE_PROGRAM CMAKE_COMMAND CMAKE_CTEST_COMMAND
               CAMBIUM_PREPROCESSOR)
    if(${tool})
      string(APPEND text "${tool}\t${${tool}}\tused\n")
    endif()
  endforeach()
  get_property(packages GLOBAL PROPERTY PACKAGES_FOUND)
  foreach(package IN LISTS packages)
    if(${package}_CONFIG)
      string(APPEND text "find_package(${package})\t${${package}_CONFIG}\tused\n")
    endif()
  endforeach()
  # Files of the targets the build links are used; those of the other targets a package
  # defines need only exist, since Debian's *Targets.cmake stop the configure otherwise.
  _cambium_linked_targets(linked)
  _cambium_directory_targets("${PROJECT_SOURCE_DIR}" IMPORTED_TARGETS targets)
  foreach(target IN LISTS targets)
    if(target MATCHES "${CAMBIUM_UNUSED_IMPORTED_TARGETS}")
      continue()
    endif()
    set(kind defined)
    if(target IN_LIST linked)
      set(kind used)
    endif()
    _cambium_target_files(${target} files)
    foreach(file IN LISTS files)
      string(APPEND text "${target}\t${file}\t${kind}\n")
    endforeach()
  endforeach()
  file(WRITE "${CMAKE_BINARY_DIR}/package-files.txt" "${text}")
endfunction()
