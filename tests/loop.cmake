# The real-time loop through the CLI. Included from tests/CMakeLists.txt where `cli` and
# `cli_out` are set.
#
# thesis-sunset on every built backend: 24 steps, 4 warm-up, a render every step after it, 4 frames a step. So the
# timed loop is 20 steps of 4 frames (80), alpha runs 1/4, 1/2, 3/4, 1 in every step, and with the automaton shade
# and shadow run on every render step (20) and on none of the 4 warm-up steps (not output steps).
set(cli_loop_sunset_script [=[d="$1"; rm -rf "$d"; set -e
"$0" run thesis-sunset --quiet --out "$d" >/dev/null || test $? -eq 4
/usr/bin/python3 - "$d/results.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["scene"]["frames_per_step"] == 4 and r["scene"]["sun_moves"] is True, r["scene"]
ok = [name for name, b in r["backends"].items() if b["status"] == "ok"]
assert "cpu" in ok, r["backends"].keys()
for name in ok:
    b = r["backends"][name]
    loop = b["loop"]
    assert loop["steps"] == 20 and loop["frames"] == 80, (name, loop)
    assert loop["fps"] > 0 and abs(loop["fps"] - 80 * 1000 / loop["wall_ms"]) < 1e-6 * loop["fps"], (name, loop)
    runs = b["stage_runs"]
    for stage in ("shade", "shadow"):
        assert runs[stage] == {"ran": 20, "skipped_unchanged": 0, "not_output_step": 4}, (name, stage, runs[stage])
    for stage in ("region", "ca", "smooth", "density"):
        assert runs[stage]["ran"] == 24, (name, stage, runs[stage])
    assert runs["render_splat"]["ran"] == 20 and runs["render_splat"]["frames"] == 80, (name, runs["render_splat"])
    for camera, frames in b["frames"].items():
        assert frames["alphas"] == [0.25, 0.5, 0.75, 1.0] * 20, (name, camera, frames["alphas"][:8])
        assert frames["steps"] == [t for t in range(4, 24) for _ in range(4)], (name, camera)
    print(name, "loop", round(loop["fps"], 1), "fps")
print("loop checked")
PY]=])
add_test(NAME Cli.LoopSunsetRun COMMAND /bin/sh -c "${cli_loop_sunset_script}" ${cli} ${cli_out}/loop-sunset)
set_tests_properties(Cli.LoopSunsetRun PROPERTIES TIMEOUT 300 PASS_REGULAR_EXPRESSION "loop checked")

# The backends agree on it, every frame of every step compared with the CPU's (exit 4, no GPU backend: a skip).
add_test(NAME Cli.LoopSunsetConform COMMAND ${cli} conform thesis-sunset --quiet --out ${cli_out}/loop-conform)
set_tests_properties(Cli.LoopSunsetConform PROPERTIES TIMEOUT 300 SKIP_RETURN_CODE 4 FAIL_REGULAR_EXPRESSION "fail ")

# A static density (noise without drift) under a sun that holds to step 2, moves on steps 3..6 and holds again:
# results.json counts shade and shadow on steps 0, 3, 4, 5, 6 only (5 ran, 5 skipped of 10), density once.
set(cli_loop_sun_script [=[d="$1"; rm -rf "$d"; set -e
cat > "$d.json" <<'JSON'
{"path": [{"step": 0, "elevation_deg": 30, "azimuth_deg": 40}, {"step": 2, "elevation_deg": 30, "azimuth_deg": 40},
          {"step": 6, "elevation_deg": 50, "azimuth_deg": 80}, {"step": 8, "elevation_deg": 50, "azimuth_deg": 80}]}
JSON
"$0" run ci-small --backend cpu --quiet --out "$d" --set steps=10 --set warmup_steps=0 --set render.every_steps=1 \
  --set 'stages=["noise","density","shade","shadow","render_splat"]' --set "sun=$(cat "$d.json")" >/dev/null
/usr/bin/python3 - "$d/results.json" <<'PY'
import json, sys
runs = json.load(open(sys.argv[1]))["backends"]["cpu"]["stage_runs"]
for stage in ("shade", "shadow"):
    assert runs[stage] == {"ran": 5, "skipped_unchanged": 5, "not_output_step": 0}, (stage, runs[stage])
assert runs["density"] == {"ran": 1, "skipped_unchanged": 9, "not_output_step": 0}, runs["density"]
assert runs["noise"]["ran"] == 1 and runs["render_splat"]["ran"] == 10, runs
print("sun counted")
PY]=])
add_test(NAME Cli.LoopMovingSunCounts COMMAND /bin/sh -c "${cli_loop_sun_script}" ${cli} ${cli_out}/loop-sun)
set_tests_properties(Cli.LoopMovingSunCounts PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION "sun counted")

# Time-slicing (SPEC 13) on every built backend: thesis-sunset at 8 slices per frame. Each step computes the next one
# over its frames, so a step draws at least its 4 frames and as many as its shares take, alpha runs (f + 1) / F over
# them, the loop reports each frame's time and the slowest frame with what it computed, and the stages run as often
# as unsliced (the automaton once less: the last step computes nothing ahead).
set(cli_loop_sliced_script [=[d="$1"; rm -rf "$d"; set -e
"$0" run thesis-sunset --quiet --out "$d" --set render.slices_per_frame=8 >/dev/null || test $? -eq 4
/usr/bin/python3 - "$d/results.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
ok = [name for name, b in r["backends"].items() if b["status"] == "ok"]
assert "cpu" in ok, r["backends"].keys()
for name in ok:
    b = r["backends"][name]
    loop = b["loop"]
    assert loop["slices_per_frame"] == 8 and loop["steps"] == 20, (name, loop)
    frames = loop["frame_ms"]
    assert frames["count"] == loop["frames"] and loop["frames"] > 80, (name, frames["count"], loop["frames"])
    assert abs(sum(frames["samples_ms"]) - loop["wall_ms"]) < 1e-6 * loop["wall_ms"], (name, "frames add up to the loop")
    assert frames["max_ms"] >= frames["median_ms"] and frames["slowest"]["step"] >= 4, (name, frames["slowest"])
    runs = b["stage_runs"]
    for stage in ("shade", "shadow"):
        assert runs[stage] == {"ran": 20, "skipped_unchanged": 0, "not_output_step": 4}, (name, stage, runs[stage])
    for stage in ("region", "smooth", "density"):
        assert runs[stage]["ran"] == 24, (name, stage, runs[stage])
    assert runs["ca"]["ran"] == 23, (name, runs["ca"])
    for camera, f in b["frames"].items():
        steps = f["steps"]
        for t in range(4, 24):
            alphas = [a for s, a in zip(steps, f["alphas"]) if s == t]
            n = len(alphas)
            assert n >= 4 and all(abs(a - (i + 1) / n) < 1e-7 for i, a in enumerate(alphas)), (name, camera, t, alphas)
    print(name, "sliced loop", round(loop["fps"], 1), "fps, slowest frame", round(frames["max_ms"], 3), "ms")
print("sliced loop checked")
PY]=])
add_test(NAME Cli.LoopTimeSlicedRun COMMAND /bin/sh -c "${cli_loop_sliced_script}" ${cli} ${cli_out}/loop-sliced)
set_tests_properties(Cli.LoopTimeSlicedRun PROPERTIES TIMEOUT 300 PASS_REGULAR_EXPRESSION "sliced loop checked")

# No state survives a call that should not: the sun sets below the horizon at step 3 and rises again by step 6, every
# step rendered, and every backend's every step must equal the CPU's. A backend that kept "no sun" set after sunset
# (gl's shadow program setting its noSun uniform only to 1) draws no shadow after sunrise: shadow fails at step 5.
add_test(NAME Cli.ConformSunsetSunrise COMMAND ${cli} conform ${CMAKE_CURRENT_SOURCE_DIR}/scenes/sunset-sunrise.json
         --out ${cli_out}/conform-sunset-sunrise)
set_tests_properties(Cli.ConformSunsetSunrise PROPERTIES TIMEOUT 120
                     PASS_REGULAR_EXPRESSION "; exit 0, every compared row conforms")
