# What `run` prints beside results.json (docs/cli.md, "run"), through the CLI. Included from tests/CMakeLists.txt
# where `cli` and `cli_out` are set.
#
# A renderer's time per camera frame in `run` and `report` is median(samples_ms) / cameras, worked from
# results.json and the scene file (wang-20km at 160x128, 3 cameras); the table's run order and "-".
add_test(NAME Cli.RunFrameFigures
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_run_output.py ${cli} ${cli_out}/run-frames frames)
# The progress end line is on stderr, and --quiet silences it.
add_test(NAME Cli.RunQuietProgress
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_run_output.py ${cli} ${cli_out}/run-quiet quiet)
