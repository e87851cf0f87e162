# Save and resume through the CLI (docs/cli.md, run --save-state / --resume; harness/run/SimulationState.h).
# Included from tests/CMakeLists.txt where `cli`, `cli_out` and `expect_exit` are set.
#
# ci-small (on a 32 x 32 x 8 grid) for 9 steps (rendered every step after 1 warm-up, jittered, short-lived ellipsoids so some are born after
# the split), once whole, and once as 5 steps saved with --save-state then resumed with --resume up to 9, on the CPU;
# again time-sliced (2 slices a frame), saved every 2 steps; and, where a GPU backend opens, saved on the CPU and
# resumed there. The resumed run's last frame (.exr and .png) and top view must equal the whole run's byte for byte (the EXR's capture date aside)
# (across backends: its cover, splat counts and the frame's PNG), its per-step cover and splat counts must equal
# steps 5..8 of the whole run's, and results.json counts only the resumed steps.
set(cli_state_script [=[d="$1"; rm -rf "$d"; mkdir -p "$d"; set -e
sets="--set warmup_steps=1 --set render.every_steps=1 --set render.frames_per_step=2 --set ellipsoids.lifetime_mean=3 \
  --set ellipsoids.lifetime_variance=1 --set ellipsoids.shrink_steps=1 --set ellipsoids.jitter=0.5 \
  --set render.width=64 --set render.height=48 --set grid.size=[32,32,8] --set density.tile=8 --set density.band=2"
run() { "$0" run ci-small --quiet $sets "$@"; }
for sliced in 0 2; do
  s="--set render.slices_per_frame=$sliced"
  run $s --backend cpu --steps 9 --out "$d/whole$sliced" >/dev/null
  run $s --backend cpu --steps 5 --out "$d/first$sliced" --save-state "$d/state$sliced" --save-state-every 2 >/dev/null
  run $s --backend cpu --steps 9 --out "$d/second$sliced" --resume "$d/state$sliced" >"$d/second$sliced.txt"
  grep -q "resuming $d/state$sliced at step 5" "$d/second$sliced.txt"
done
# Another backend resumes the CPU's state, where one opens (exit 4: none here).
gpu=""
for b in vk gl; do
  if run --set render.slices_per_frame=0 --backend $b --steps 9 --out "$d/whole-$b" >/dev/null 2>&1; then
    gpu=$b; break
  fi
done
if [ -n "$gpu" ]; then
  run --set render.slices_per_frame=0 --backend $gpu --steps 9 --out "$d/second-$gpu" --resume "$d/state0" >/dev/null
fi
/usr/bin/python3 - "$d" "$gpu" <<'PY'
import json, re, sys
d, gpu = sys.argv[1], sys.argv[2]
def same(a, b):
    # Byte for byte, but for the EXR header's capture date (OpenImageIO writes the time of writing).
    date = re.compile(rb"capDate\x00string\x00.{4}\d{4}:\d\d:\d\d \d\d:\d\d:\d\d", re.S)
    return date.sub(b"", open(a, "rb").read()) == date.sub(b"", open(b, "rb").read())
def results(folder): return json.load(open(f"{d}/{folder}/results.json"))["backends"]
def frames(b):
    f = b["frames"]["above"]
    return list(zip(f["steps"], f["splats"]))
for sliced in ("0", "2"):
    whole, second = results("whole" + sliced)["cpu"], results("second" + sliced)["cpu"]
    assert whole["status"] == "ok" and second["status"] == "ok", (whole["status"], second["status"])
    assert second["steps_completed"] == 4, second["steps_completed"]
    assert second["cover"] == whole["cover"][5:], (second["cover"], whole["cover"])
    assert max(whole["cover"][5:]) > 0, "the test needs clouds"
    assert frames(second) == [f for f in frames(whole) if f[0] >= 5], (frames(second), frames(whole))
    for name in ("frame-splat-above-cpu.exr", "frame-splat-above-cpu.png", "topview-cpu.png"):
        assert same(f"{d}/whole{sliced}/{name}", f"{d}/second{sliced}/{name}"), (sliced, name)
    manifest = json.load(open(f"{d}/state{sliced}/manifest.json"))
    assert manifest["format"] == "cloudbench-simulation-state" and manifest["version"] == 1, manifest["format"]
    assert manifest["step"] == 5, manifest["step"]
    print("slices", sliced, ": resumed at 5 == whole run; cover", second["cover"])
if gpu:
    whole, second = results("whole-" + gpu)[gpu], results("second-" + gpu)[gpu]
    assert second["status"] == "ok", second
    assert second["cover"] == whole["cover"][5:], (second["cover"], whole["cover"])
    assert frames(second) == [f for f in frames(whole) if f[0] >= 5], (frames(second), frames(whole))
    name = f"frame-splat-above-{gpu}.png"
    assert same(f"{d}/whole-{gpu}/{name}", f"{d}/second-{gpu}/{name}"), name
    print("cpu state resumed on", gpu, "== its whole run")
else:
    print("no GPU backend here: the cross-backend resume was not run")
PY
echo "state resume ok"]=])
add_test(NAME Cli.StateSplitRunEqualsWholeRun COMMAND sh -c "${cli_state_script}" ${cli} ${cli_out}/state)
set_tests_properties(Cli.StateSplitRunEqualsWholeRun PROPERTIES PASS_REGULAR_EXPRESSION "state resume ok")

# Refusals: a state and a scene of other settings exit 3 naming the file, the field and the reason; --save-state
# with two backends, or --save-state-every alone, exit 2 before any work.
add_test(NAME Cli.StateOtherSettingsExits3 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=run;ci-small;--backend;cpu;--set;ca.seed=8;--resume;${cli_out}/state/state0;--out;${cli_out}/state-bad"
         -DEXPECT=3 ${expect_exit})
set_tests_properties(Cli.StateOtherSettingsExits3 PROPERTIES DEPENDS Cli.StateSplitRunEqualsWholeRun)
add_test(NAME Cli.StateOtherSettingsMessage COMMAND ${cli} run ci-small --backend cpu --steps 9 --set warmup_steps=1
         --set ca.seed=8
         --resume ${cli_out}/state/state0 --out ${cli_out}/state-bad)
set_tests_properties(Cli.StateOtherSettingsMessage PROPERTIES DEPENDS Cli.StateSplitRunEqualsWholeRun
                     PASS_REGULAR_EXPRESSION "state0/manifest.json: scene.settings_hash: saved with other scene settings")
add_test(NAME Cli.StateMissingExits3 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=run;ci-small;--backend;cpu;--resume;${cli_out}/state/nonexistent;--out;${cli_out}/state-bad"
         -DEXPECT=3 ${expect_exit})
add_test(NAME Cli.StateTwoBackendsExits2 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=run;ci-small;--backend;cpu,vk;--save-state;${cli_out}/state/two;--out;${cli_out}/state-bad"
         -DEXPECT=2 ${expect_exit})
add_test(NAME Cli.StateEveryAloneExits2 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=run;ci-small;--backend;cpu;--save-state-every;2;--out;${cli_out}/state-bad"
         -DEXPECT=2 ${expect_exit})
