# The mutation-testing tool (tools/mutate.py, docs/testing.md "Mutation testing"), included from tests/CMakeLists.txt.
# The full run is slow and on demand; this cheap check keeps the mutant set from going stale: every mutant's `find`
# text must occur exactly once in its file, and every field must be present.
add_test(NAME Tools.MutantsApply COMMAND /usr/bin/python3 ${CLOUDBENCH_ROOT}/tools/mutate.py --check --tree ${CLOUDBENCH_ROOT})
set_tests_properties(Tools.MutantsApply PROPERTIES TIMEOUT 30 PASS_REGULAR_EXPRESSION "all [0-9]+ mutants apply")
# The CTest oracle's default choice of tests: every unit test (the gate's statistics among them) and every test
# outside the slow groups, which it leaves out by their label.
add_test(NAME Tools.MutateOracleKeepsFastTests
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_mutate_oracle.py ${CLOUDBENCH_ROOT}/tools/mutate.py
                 ${CMAKE_BINARY_DIR})
set_tests_properties(Tools.MutateOracleKeepsFastTests PROPERTIES TIMEOUT 60 PASS_REGULAR_EXPRESSION
                     "the ctest oracle runs [0-9]+ of [0-9]+ tests" FAIL_REGULAR_EXPRESSION "FAIL: ")
