# render_march on Vulkan from the command line (issue 14 items 2 and 4): `conform` against the CPU with
# the Khronos validation layer on (CLOUDBENCH_VK_VALIDATION=1; any message fails the test), over the
# options: the defaults, the light march with Mie, jitter, adaptive steps, powder and the lightning
# point light, odd sizes without skipping, and the noise scene. Included from tests/CMakeLists.txt.
set(march_vk_scene ${CMAKE_CURRENT_SOURCE_DIR}/scenes/imgacc-small.json)
set(march_vk_stages "stages=[\"noise\",\"density\",\"shade\",\"render_march\"]")
set(march_vk_cases
    "Defaults|${march_vk_scene}|--set|${march_vk_stages}"
    "LightMarchMieJitterAdaptivePowderPoint|${march_vk_scene}|--set|${march_vk_stages}|--set|march.light=\"march\"|--set|phase.function=\"mie\"|--set|march.jitter=true|--set|march.adaptive.enabled=true|--set|march.adaptive.start=4|--set|march.powder.enabled=true|--set|lightning.position=[20,20,10]|--set|lightning.intensity=5000"
    "OddSizesNoSkipping|${march_vk_scene}|--set|${march_vk_stages}|--set|grid.size=[31,29,13]|--set|render.width=67|--set|render.height=45|--set|march.skipping.enabled=false|--set|phase.function=\"cornette-shanks\""
    "OddSizesBrick3|${march_vk_scene}|--set|${march_vk_stages}|--set|grid.size=[31,29,13]|--set|march.skipping.brick=3|--set|march.light=\"march\"|--set|phase.function=\"none\""
    "NoiseLayer|${CMAKE_CURRENT_SOURCE_DIR}/../scenes/noise-layer.json|--set|render.width=160|--set|render.height=90"
    "NoiseLayerBrick1LightMarch|${CMAKE_CURRENT_SOURCE_DIR}/../scenes/noise-layer.json|--set|render.width=97|--set|render.height=61|--set|march.skipping.brick=1|--set|march.light=\"march\"")
foreach(entry ${march_vk_cases})
  string(REPLACE "|" ";" fields "${entry}")
  list(POP_FRONT fields name scene)
  add_test(NAME Cli.ConformMarchVk${name}
           COMMAND ${CMAKE_COMMAND} -E env CLOUDBENCH_VK_VALIDATION=1
                   ${cli} conform ${scene} --backend cpu,vk --out ${cli_out}/conform-march-vk-${name} ${fields})
  set_tests_properties(Cli.ConformMarchVk${name} PROPERTIES PASS_REGULAR_EXPRESSION "render_march +vk +pass"
                       FAIL_REGULAR_EXPRESSION "vk validation|render_march +vk +fail")
endforeach()
