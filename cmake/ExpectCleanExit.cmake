# Runs CMD with ARGS (a ;-list) and fails unless it exits with one of EXPECT (a ;-list of codes) and neither of its
# output streams holds a sanitizer report (tests/sanitized.cmake). A process killed by a signal fails: execute_process
# gives its reason ("Child aborted") instead of a number.
cmake_minimum_required(VERSION 3.25)
execute_process(COMMAND ${CMD} ${ARGS} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(report_pattern "runtime error:|ERROR: AddressSanitizer|ERROR: LeakSanitizer|SUMMARY: (Address|Undefined|Leak)")
if(NOT rc IN_LIST EXPECT)
  message(FATAL_ERROR "expected exit code ${EXPECT}, got ${rc}\nstdout: ${out}\nstderr: ${err}")
endif()
if("${out}${err}" MATCHES "${report_pattern}")
  message(FATAL_ERROR "sanitizer report (exit code ${rc})\nstdout: ${out}\nstderr: ${err}")
endif()
string(LENGTH "${err}" err_length)
if(err_length GREATER 400)
  string(SUBSTRING "${err}" 0 400 err)
  string(APPEND err "...")
endif()
message(STATUS "exit code ${rc} as expected, no sanitizer report; stderr: ${err}")
