# The ground in the frame through `cloudbench conform`: the shipped scene ground-shadow draws
# the ground lit through G with both renderers; every built backend renders from the CPU's inputs (G among them)
# and is compared by SPEC 8's and SPEC 10's image rules (conform exits 5 on a failure). The Khronos validation
# layer is on (CLOUDBENCH_VK_VALIDATION=1) and any message fails the test, as does a renderer that a backend skips.
# Included from tests/CMakeLists.txt where `cli` and `cli_out` are set.
set(ground_backends cpu)
if(CLOUDBENCH_HAVE_GL)
  string(APPEND ground_backends ",gl")
endif()
if(CLOUDBENCH_HAVE_VK)
  string(APPEND ground_backends ",vk")
endif()
add_test(NAME Cli.ConformGroundShadow
         COMMAND ${CMAKE_COMMAND} -E env CLOUDBENCH_VK_VALIDATION=1
                 ${cli} conform ${CMAKE_CURRENT_SOURCE_DIR}/../scenes/ground-shadow.json --backend ${ground_backends} --out ${cli_out}/conform-ground --steps 3)
set_tests_properties(Cli.ConformGroundShadow PROPERTIES
                     FAIL_REGULAR_EXPRESSION "vk validation|render_(splat|march) +(vk|gl) +(fail|skipped)")
