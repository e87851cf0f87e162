# The manual against the tree: the README's and docs/scenes.md's scene tables list every shipped scene.
# Included from tests/CMakeLists.txt.
add_test(NAME Docs.EveryShippedSceneListed
         COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/check_docs_scenes.py ${CLOUDBENCH_ROOT})
set_tests_properties(Docs.EveryShippedSceneListed PROPERTIES PASS_REGULAR_EXPRESSION "docs list every scene")

# Every command's help names every option it accepts: a binary of its own, since only the CLI links the commands'
# registrations (harness/CMakeLists.txt, cloudbench_commands).
add_executable(cloudbench_help_tests HelpListsOptionsTest.cpp)
target_link_libraries(cloudbench_help_tests PRIVATE cloudbench_commands cloudbench_harness GTest::gtest_main)
gtest_discover_tests(cloudbench_help_tests DISCOVERY_TIMEOUT 60)
