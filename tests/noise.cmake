# Stage noise from the command line: the test noise scene runs end to end on the CPU
# (noise, density, shade, shadow, render_splat) and writes its results. Included from tests/CMakeLists.txt.
add_test(NAME Cli.RunNoiseSmall
         COMMAND ${cli} run ${CMAKE_CURRENT_SOURCE_DIR}/scenes/noise-small.json --backend cpu --quiet
                 --out ${cli_out}/noise-small)
set_tests_properties(Cli.RunNoiseSmall PROPERTIES PASS_REGULAR_EXPRESSION "results: .*results.json")
# The noise scene conforms on every backend (noise |dq| <= 1e-5 against the CPU; exit 5 otherwise).
add_test(NAME Cli.ConformNoiseSmall
         COMMAND ${cli} conform ${CMAKE_CURRENT_SOURCE_DIR}/scenes/noise-small.json --backend cpu,gl,vk
                 --out ${cli_out}/conform-noise-small)
set_tests_properties(Cli.ConformNoiseSmall PROPERTIES PASS_REGULAR_EXPRESSION "noise +vk +pass")
