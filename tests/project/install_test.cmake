# SPDX-License-Identifier: Apache-2.0
# cmake -DBUILD=<cambium build> -DCONSUMER=<project> -DWORK=<scratch> -P install_test.cmake
# Installs the build into WORK/prefix, then configures, builds and runs CONSUMER against it.
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${what} failed (${status}):\n${out}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK}")
run(install ${CMAKE_COMMAND} --install "${BUILD}" --prefix "${WORK}/prefix")
# A consumer needs what the exported targets link, and OpenImageIO is not among them (only
# the dlopen'ed image module links it): neither the targets nor the package may ask for it.
file(GLOB package_files "${WORK}/prefix/lib*/cmake/cambium/*.cmake")
if(NOT package_files)
  message(FATAL_ERROR "no CMake package files installed under ${WORK}/prefix")
endif()
foreach(f ${package_files})
  file(STRINGS "${f}" oiio REGEX "^[^#]*(OpenImageIO|Imath)")
  if(oiio)
    message(FATAL_ERROR "${f} asks a consumer for OpenImageIO: ${oiio}")
  endif()
endforeach()
run(configure ${CMAKE_COMMAND} -S "${CONSUMER}" -B "${WORK}/build" -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_PREFIX_PATH=${WORK}/prefix")
run(build ${CMAKE_COMMAND} --build "${WORK}/build")
run(consumer "${WORK}/build/consumer")
message("${output}")
