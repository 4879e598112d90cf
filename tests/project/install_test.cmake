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
run(configure ${CMAKE_COMMAND} -S "${CONSUMER}" -B "${WORK}/build" -DCMAKE_BUILD_TYPE=Release
    "-DCMAKE_PREFIX_PATH=${WORK}/prefix")
run(build ${CMAKE_COMMAND} --build "${WORK}/build")
run(consumer "${WORK}/build/consumer")
message("${output}")
