# render_march conforms on every built backend through `cloudbench conform`: each
# backend renders from the CPU's inputs and is compared by SPEC 10's rule (max |d| <= 1e-4 per linear channel
# on 99.9 % of pixels; conform exits 5 on a failure). The Khronos validation layer is on
# (CLOUDBENCH_VK_VALIDATION=1) and any message fails the test, as does a backend that skips the stage.
# Each case runs every built GPU backend in one command (each in its own process, with its own CPU reference).
# Included from tests/CMakeLists.txt where `cli` and `cli_out` are set.
set(march_backends cpu)
if(CLOUDBENCH_HAVE_GL)
  string(APPEND march_backends ",gl")
endif()
if(CLOUDBENCH_HAVE_VK)
  string(APPEND march_backends ",vk")
endif()
set(march_small ${CMAKE_CURRENT_SOURCE_DIR}/scenes/imgacc-small.json)
set(march_layer ${CMAKE_CURRENT_SOURCE_DIR}/../scenes/noise-layer.json)
set(march_stages "stages=[\"noise\",\"density\",\"shade\",\"render_march\"]")
set(march_cases
    # The noise test scene (32x32x16, 64x48) as it is.
    "Small|${march_small}|--set|${march_stages}"
    # ci-small: the automaton's clouds over three steps (q moves between them; alpha interpolates).
    "CiSmall|ci-small|--steps|3|--set|stages=[\"region\",\"ca\",\"smooth\",\"density\",\"shade\",\"render_march\"]"
    # An odd grid and image with every non-default option at once: jitter, no skipping, the adaptive step,
    # the light march, powder, the Mie phase and the lightning (flashing at step 0).
    "OddEveryOption|${march_small}|--set|stages=[\"noise\",\"density\",\"render_march\"]|--set|grid.size=[31,29,13]|--set|render.width=37|--set|render.height=23|--set|march.jitter=true|--set|march.skipping.enabled=false|--set|march.adaptive.enabled=true|--set|march.adaptive.start=8|--set|march.light=\"march\"|--set|march.light_steps=4|--set|march.powder.enabled=true|--set|phase.function=\"mie\"|--set|lightning.position=[800,700,300]|--set|lightning.intensity=200000"
    "OddNoSkippingCornetteShanks|${march_small}|--set|${march_stages}|--set|grid.size=[31,29,13]|--set|render.width=67|--set|render.height=45|--set|march.skipping.enabled=false|--set|phase.function=\"cornette-shanks\""
    "OddBrick3LightMarchNoPhase|${march_small}|--set|${march_stages}|--set|grid.size=[31,29,13]|--set|march.skipping.brick=3|--set|march.light=\"march\"|--set|phase.function=\"none\""
    # The dual lobe, mostly backward (its peak at cos theta = -1), with the light march and the lightning.
    "OddDualLobeLightMarch|${march_small}|--set|${march_stages}|--set|grid.size=[31,29,13]|--set|render.width=67|--set|render.height=45|--set|march.light=\"march\"|--set|phase.function=\"dual-lobe\"|--set|phase.g_backward=-0.7|--set|phase.blend=0.8|--set|lightning.position=[800,700,300]|--set|lightning.intensity=200000"
    # The shipped noise scene (128^3) at small images.
    "NoiseLayer|${march_layer}|--steps|1|--set|render.width=160|--set|render.height=90"
    "NoiseLayerBrick1LightMarch|${march_layer}|--steps|1|--set|render.width=97|--set|render.height=61|--set|march.skipping.brick=1|--set|march.light=\"march\"")
foreach(entry ${march_cases})
  string(REPLACE "|" ";" fields "${entry}")
  list(POP_FRONT fields name scene)
  add_test(NAME Cli.ConformMarch${name}
           COMMAND ${CMAKE_COMMAND} -E env CLOUDBENCH_VK_VALIDATION=1
                   ${cli} conform ${scene} --backend ${march_backends} --out ${cli_out}/conform-march-${name} ${fields})
  set_tests_properties(Cli.ConformMarch${name} PROPERTIES
                       FAIL_REGULAR_EXPRESSION "vk validation|render_march +(vk|gl) +(fail|skipped)")
endforeach()
# conform reports a renderer's worst pixel with a difference image: with powder (GLSL's pow
# against glibc's, ~1e-7 apart) the GPU backends' images differ slightly, and each render_march row that
# differs names diff-render_march-<backend>.exr in the output folder, whose largest value is the row's worst.
set(march_diff_script [=[d="$1"; rm -rf "$d"; set -e
"$0" conform "$2/scenes/imgacc-small.json" --backend "$3" --out "$d" \
  --set 'stages=["noise","density","shade","render_march"]' --set march.powder.enabled=true >/dev/null
/usr/bin/python3 - "$d" "$2" <<'PY'
import json, pathlib, sys
sys.path.insert(0, sys.argv[2])
from check_bad_inputs import exr_floats
d = pathlib.Path(sys.argv[1])
rows = [r for r in json.load(open(d / "conform.json"))["results"] if r["stage"] == "render_march"]
differing = [r for r in rows if r["worst"] > 0]
assert differing, "no backend differs from the CPU: the test would prove nothing here"
for r in rows:
    if r["worst"] == 0:
        assert r["difference_image"] == "", r
        continue
    assert r["difference_image"] == "diff-render_march-%s.exr" % r["backend"], r
    pixels = exr_floats(d / r["difference_image"])
    assert pixels.size == 64 * 48 * 3, pixels.size
    assert abs(float(pixels.max()) - r["worst"]) <= 1e-6 * max(1.0, r["worst"]), (pixels.max(), r["worst"])
    print("difference image", r["backend"], r["worst"])
PY]=])
if(CLOUDBENCH_HAVE_GL OR CLOUDBENCH_HAVE_VK)
  string(REPLACE "cpu," "" march_gpu_backends "${march_backends}")
  add_test(NAME Cli.ConformMarchWritesDifferenceImages
           COMMAND /bin/sh -c "${march_diff_script}" ${cli} ${cli_out}/conform-march-diff ${CMAKE_CURRENT_SOURCE_DIR}
                   cpu,${march_gpu_backends})
  set_tests_properties(Cli.ConformMarchWritesDifferenceImages PROPERTIES PASS_REGULAR_EXPRESSION "difference image (gl|vk) [0-9]")
endif()
