# Each command's own options (harness/platform/Command.h): every own option
# parses into its command's options and refuses a bad value with exit 2;
# another command's option is unknown. Included from tests/CMakeLists.txt,
# where `cli` is defined.
add_test(NAME Cli.CommandOptions
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_command_options.py ${cli})
set_tests_properties(Cli.CommandOptions PROPERTIES PASS_REGULAR_EXPRESSION "command options: ok" TIMEOUT 300)
