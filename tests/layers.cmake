# render_layers through the CLI: `run` writes its frames and counters, and it conforms on every built backend
# through `cloudbench conform` (SPEC 8's image rule; exit 5 on a failure), with the Khronos validation layer on
# (any message fails the test, as does a backend that skips the stage). Included from tests/CMakeLists.txt where
# `cli` and `cli_out` are set; march_backends comes from march_conform.cmake.
set(layers_cases
    # The shipped small scene: tiled, 8 layers, the eye below, inside and above the layer.
    "Small|layers-small"
    # Not tiled, half and twice the layers, a short l_max, the Mie phase, an odd grid and image.
    "UntiledHalfLayersMie|layers-small|--set|grid.tiling=false|--set|layers.count=4|--set|phase.function=\"mie\"|--set|grid.size=[31,29,9]|--set|render.width=67|--set|render.height=45"
    "TwiceLayersShortPathCornetteShanks|layers-small|--set|layers.count=16|--set|layers.max_length=1.5|--set|phase.function=\"cornette-shanks\"|--set|layers.extent=6000"
    # The dual lobe at its defaults, LOD0's billboards on.
    "DualLobeLod0|layers-small|--set|phase.function=\"dual-lobe\"|--set|layers.lod0_radius=1500"
    # The wind's drift (eq. 18) over three steps, with alpha interpolating between them.
    "WindThreeSteps|layers-small|--steps|3|--set|layers.wind=[170,-45]|--set|render.alpha=0.4"
    # Wang, Ji and Zhang's opacity (eq. 16) with its modulation map, tiled and not.
    "WangOpacity|layers-small|--set|layers.wang={\"coverage\":0.8,\"density\":2.5,\"frequency\":[2,1]}"
    "WangOpacityUntiled|layers-small|--set|grid.tiling=false|--set|layers.wang={\"coverage\":0.9,\"octaves\":2}"
    # Relighting under a moving sun: T shaded once, scaled per step.
    "RelightMovingSun|layers-small|--steps|3|--set|sun.speed={\"azimuth_deg\":12}|--set|layers.relight=\"vector\""
    # LOD0's billboards around each eye (below, inside and above the layer), at the voxel spacing, and untiled with
    # wider spacing, the wang opacity and the wind.
    "Lod0|layers-small|--set|layers.lod0_radius=1500"
    "Lod0SpacingUntiledWang|layers-small|--steps|2|--set|grid.tiling=false|--set|layers.lod0_radius=2500|--set|layers.billboard_spacing=230|--set|layers.wind=[170,-45]|--set|layers.wang={\"coverage\":0.8,\"density\":2.5}")
foreach(entry ${layers_cases})
  string(REPLACE "|" ";" fields "${entry}")
  list(POP_FRONT fields name scene)
  add_test(NAME Cli.ConformLayers${name}
           COMMAND ${CMAKE_COMMAND} -E env CLOUDBENCH_VK_VALIDATION=1
                   ${cli} conform ${scene} --backend ${march_backends} --out ${cli_out}/conform-layers-${name} ${fields})
  set_tests_properties(Cli.ConformLayers${name} PROPERTIES
                       FAIL_REGULAR_EXPRESSION "vk validation|render_layers +(vk|gl) +(fail|skipped)")
endforeach()
# `run` writes each camera's frame as EXR and PNG and the counters in results.json's layers_frames.
set(cli_layers_script [=[d="$1"; rm -rf "$d"; set -e
"$0" run layers-small --backend cpu --quiet --out "$d" >/dev/null
for c in below inside above; do test -s "$d/frame-layers-$c-cpu.png" && test -s "$d/frame-layers-$c-cpu.exr"; done
/usr/bin/python3 - "$d" <<'PY'
import json, sys
frames = json.load(open(sys.argv[1] + "/results.json"))["backends"]["cpu"]["layers_frames"]
for camera in ("below", "inside", "above"):
    f = frames[camera]
    assert 0 < f["drawn"][-1] <= f["fragments"][-1], (camera, f)
print("frames and counters")
PY]=])
add_test(NAME Cli.LayersRunWritesFrames COMMAND /bin/sh -c "${cli_layers_script}" ${cli} ${cli_out}/layers-run)
set_tests_properties(Cli.LayersRunWritesFrames PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION "frames and counters")
# tools/wang_fps.py keeps working: one quick round on every built backend, a track average per scene and backend with
# the paper's figure beside it, and no backend left unmeasured. Not a measurement.
add_test(NAME Cli.WangFpsQuick COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/../tools/wang_fps.py --quick
                                       --cli ${cli} --backends ${march_backends} --out ${cli_out}/wang-fps-quick)
set_tests_properties(Cli.WangFpsQuick PROPERTIES TIMEOUT 180
  PASS_REGULAR_EXPRESSION "\\| wang-20km \\| cpu \\| track average \\|[^\n]*up to 390 fps.*\\| wang-90km \\| cpu \\| track average \\|[^\n]*still exceeding 350 fps"
  FAIL_REGULAR_EXPRESSION "not measured")
# Relighting (layers.relight "vector") shades once under a moving sun, where "shade" shades every step; and
# tools/relight_error.py keeps working (one quick round: a row per step and camera, and shade's time both ways).
set(cli_relight_script [=[d="$1"; rm -rf "$d"; set -e
for m in shade vector; do
  "$0" run layers-small --backend cpu --quiet --out "$d/$m" --steps 3 --set render.every_steps=1 \
    --set 'sun.speed={"azimuth_deg":15}' --set "layers.relight=\"$m\"" >/dev/null
done
/usr/bin/python3 - "$d" <<'PY'
import json, sys
runs = {m: json.load(open(f"{sys.argv[1]}/{m}/results.json"))["backends"]["cpu"]["stage_runs"]["shade"]["ran"]
        for m in ("shade", "vector")}
assert runs == {"shade": 3, "vector": 1}, runs
print("relight: ok")
PY]=])
add_test(NAME Cli.LayersRelightShadesOnce COMMAND bash -c "${cli_relight_script}" ${cli} ${cli_out}/relight)
set_tests_properties(Cli.LayersRelightShadesOnce PROPERTIES PASS_REGULAR_EXPRESSION "relight: ok")
add_test(NAME Cli.RelightErrorQuick COMMAND /usr/bin/python3 ${CMAKE_CURRENT_SOURCE_DIR}/../tools/relight_error.py
                                            --quick --cli ${cli} --out ${cli_out}/relight-quick)
set_tests_properties(Cli.RelightErrorQuick PROPERTIES TIMEOUT 120
  PASS_REGULAR_EXPRESSION "\\| 2 \\| [0-9.]+ \\| below \\| [0-9.e-]+ \\| [0-9.]+ \\|.*relight vector: [0-9.]+")
# accuracy measures render_layers against the exact reference render at 1/2, 1, 2 and 4 layers per voxel and from
# grazing views, and more layers come closer to it (untiled); on the tiled scene the reference repeats the volume
# too, and the layers and the march are measured against it.
set(cli_layers_accuracy_script [=[d="$1"; rm -rf "$d"; set -e
"$0" accuracy layers-small --backend cpu --quiet --out "$d/untiled" --set grid.tiling=false >/dev/null
"$0" accuracy layers-small --backend cpu --quiet --out "$d/tiled" --set 'stages=["noise","shade","render_march","render_layers"]' >/dev/null
/usr/bin/python3 - "$d" <<'PY'
import json, sys
rows = [r for r in json.load(open(sys.argv[1] + "/untiled/accuracy.json"))["image_rows"] if r["renderer"] == "render_layers"]
psnr = {r["label"]: r["error"]["psnr_db"] for r in rows if r["status"] == "ok"}
counts = {k for k in psnr if not k.startswith("render.cameras=")}
assert counts == {"(scene)", "layers.count=4", "layers.count=16", "layers.count=32"}, psnr
assert psnr["layers.count=4"] < psnr["(scene)"] < psnr["layers.count=16"], psnr
for degrees in (1, 5, 20):  # the grazing views, one row each
    assert sum(f'"elevation-{degrees}"' in k for k in psnr) == 1, (degrees, psnr)
tiled = [r for r in json.load(open(sys.argv[1] + "/tiled/accuracy.json"))["image_rows"]
         if r["label"] == "(scene)" and r["renderer"] in ("render_layers", "render_march")]
assert {r["renderer"] for r in tiled} == {"render_layers", "render_march"}, tiled
assert all(r["status"] == "ok" and r["error"]["psnr_db"] > 15 for r in tiled), tiled
print("layers accuracy: ok")
PY]=])
add_test(NAME Cli.LayersAccuracyOverLayerCounts COMMAND bash -c "${cli_layers_accuracy_script}" ${cli} ${cli_out}/layers-accuracy)
set_tests_properties(Cli.LayersAccuracyOverLayerCounts PROPERTIES PASS_REGULAR_EXPRESSION "layers accuracy: ok")
# A sweep over layers.* measures render_layers alone (the scene's march would give the same image at every point).
set(cli_layers_sweep_script [=[d="$1"; rm -rf "$d"; set -e
"$0" sweep layers-small --backend cpu --quiet --out "$d" --set grid.tiling=false \
  --set 'stages=["noise","density","shade","render_march","render_layers"]' --vary layers.count=4,16 >/dev/null
/usr/bin/python3 - "$d" <<'PY'
import json, sys
rows = json.load(open(sys.argv[1] + "/sweep.json"))["rows"]
assert {r["stage"] for r in rows} == {"render_layers"}, {r["stage"] for r in rows}
assert len(rows) == 2 and all(r["status"] == "ok" for r in rows), rows
print("layers sweep: ok")
PY]=])
add_test(NAME Cli.LayersSweepMeasuresLayersAlone COMMAND bash -c "${cli_layers_sweep_script}" ${cli} ${cli_out}/layers-sweep)
set_tests_properties(Cli.LayersSweepMeasuresLayersAlone PROPERTIES PASS_REGULAR_EXPRESSION "layers sweep: ok")
