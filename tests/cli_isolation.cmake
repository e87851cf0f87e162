# Crash isolation (harness/platform/Isolation.h): backends killed on
# purpose through the test-only CLOUDBENCH_TEST_FAULT switch (docs/cli.md).
# Included from tests/CMakeLists.txt, where `cli` and `cli_out` are defined.
set(isolation_cases oom noisolation-oom parentkill)
if(CLOUDBENCH_HAVE_GL)
  # gl is the backend killed; cpu and vk (run or reported unavailable) must keep their results.
  list(APPEND isolation_cases run conform accuracy sweep hang)
endif()
foreach(case IN LISTS isolation_cases)
  add_test(NAME Cli.Isolation.${case}
           COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_isolation.py ${cli} ${cli_out}/isolation ${case})
  set_tests_properties(Cli.Isolation.${case} PROPERTIES PASS_REGULAR_EXPRESSION "isolation ${case}: ok" TIMEOUT 600
                       # the huge allocation of the oom fault must fail as std::bad_alloc under the sanitizers too
                       ENVIRONMENT "ASAN_OPTIONS=allocator_may_return_null=1:detect_leaks=0")
endforeach()
