# The mutation-testing tool (tools/mutate.py, docs/testing.md "Mutation testing"), included from tests/CMakeLists.txt.
# The full run is slow and on demand; this cheap check keeps the mutant set from going stale: every mutant's `find`
# text must occur exactly once in its file, and every field must be present.
add_test(NAME Tools.MutantsApply COMMAND /usr/bin/python3 ${CLOUDBENCH_ROOT}/tools/mutate.py --check --tree ${CLOUDBENCH_ROOT})
set_tests_properties(Tools.MutantsApply PROPERTIES TIMEOUT 30 PASS_REGULAR_EXPRESSION "all [0-9]+ mutants apply")
