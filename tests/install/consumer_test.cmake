# Installs the built project into a scratch prefix, then configures, builds
# and runs tests/install/consumer against it with find_package(DiffPD
# COMPONENTS <COMPONENTS>) (COMPONENTS: comma-separated, e.g. "ceres,ipopt").
set(prefix "${WORK_DIR}/prefix")
set(consumer_build "${WORK_DIR}/consumer-build")
file(REMOVE_RECURSE "${WORK_DIR}")
foreach(step
    "${CMAKE_COMMAND};--install;${BUILD_DIR};--prefix;${prefix}"
    "${CMAKE_COMMAND};-S;${SOURCE_DIR}/tests/install/consumer;-B;${consumer_build};-DCMAKE_BUILD_TYPE=Release;-DCMAKE_PREFIX_PATH=${prefix};-DDIFFPD_CONSUMER_COMPONENTS=${COMPONENTS}"
    "${CMAKE_COMMAND};--build;${consumer_build};-j2"
    "${consumer_build}/consumer")
  execute_process(COMMAND ${step} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "consumer test step failed (${rc}): ${step}\n${out}\n${err}")
  endif()
endforeach()
message(STATUS "${out}")
