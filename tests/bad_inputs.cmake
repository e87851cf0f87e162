# The bad-input corpus (tests/bad_inputs/): every case through the release CLI, `run` and `dump` for
# scene cases. check_bad_inputs.py prints the outcome table; it fails on any wrong exit code or message, raw
# control byte, oversized stderr, timeout, or NaN/Inf in the outputs of a case that exits 0.
# Included from tests/CMakeLists.txt where `cli` is defined.
add_test(NAME Cli.BadInputsRefusedClearly
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_bad_inputs.py --cli ${cli} --jobs 2)
set_tests_properties(Cli.BadInputsRefusedClearly PROPERTIES TIMEOUT 900)
