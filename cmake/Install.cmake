# SPDX-License-Identifier: Apache-2.0
# `cmake --install build --prefix P` installs the cambium command, the static libraries,
# their headers (P/include/cambium/<layer>/...) and a CMake package, so another project can
#   find_package(cambium 0.1 REQUIRED)
#   target_link_libraries(app PRIVATE cambium::render)   # or cambium::lsys, ::geom, ...
# The libraries link Embree, TBB, FreeType, fontconfig, cairo, CLI11, fmt and nlohmann-json
# privately; the package finds them again for the consumer's link
# (cmake/cambiumConfig.cmake.in). OpenImageIO is linked only into
# libcambium_imageio.so, installed into the library folder (src/render/CMakeLists.txt),
# which image output and textures dlopen on first use.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(CAMBIUM_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/cambium)
foreach(layer base lsys geom env render vector app)
  set_target_properties(cambium_${layer} PROPERTIES EXPORT_NAME ${layer})
endforeach()
# The static libraries name the warning flags' target in their link interface.
set_target_properties(cambium_warnings PROPERTIES EXPORT_NAME warnings)

install(TARGETS cambium cambium_base cambium_lsys cambium_geom cambium_env cambium_render cambium_vector
                cambium_app
                cambium_warnings
  EXPORT cambiumTargets
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cambium)
install(DIRECTORY src/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/cambium
  FILES_MATCHING PATTERN "*.h" PATTERN "*.def")
install(EXPORT cambiumTargets NAMESPACE cambium:: DESTINATION ${CAMBIUM_INSTALL_CMAKEDIR})

configure_package_config_file(cmake/cambiumConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cambiumConfig.cmake
  INSTALL_DESTINATION ${CAMBIUM_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the interfaces.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/cambiumConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/cambiumConfig.cmake ${PROJECT_BINARY_DIR}/cambiumConfigVersion.cmake
  DESTINATION ${CAMBIUM_INSTALL_CMAKEDIR})
