# Image accuracy through the CLI (docs/accuracy.md, "Images"). Included from
# tests/CMakeLists.txt where `cli` and `cli_out` are set. The scene tests/scenes/imgacc-small.json is
# a 32x32x16 noise layer rendered at 64x48 by render_march and render_splat.
# accuracy: image rows with finite errors and PSNR; a step 4x the scene's has a larger mean error than
# half of it; n_l = 16 beats n_l = 2; skipping on and off have equal errors; the splat row is there.
set(cli_imgacc_accuracy_script [=[d="$1"; rm -rf "$d"; set -e
"$0" accuracy "$2/scenes/imgacc-small.json" --backend cpu --repeat 1 --quiet --out "$d" >/dev/null
/usr/bin/python3 - "$d/accuracy.json" <<'PY'
import json, math, sys
doc = json.load(open(sys.argv[1]))
rows = doc["image_rows"]
def row(renderer, label):
    found = [r for r in rows if r["renderer"] == renderer and r["label"] == label and r["backend"] == "cpu"]
    assert len(found) == 1, (renderer, label, [r["label"] for r in rows])
    assert found[0]["status"] == "ok", found[0]
    return found[0]["error"]
for r in rows:
    if r["status"] == "ok":
        e = r["error"]
        assert all(math.isfinite(e[k]) for k in ("max", "mean", "p99")), r
        assert e["psnr_db"] is None or math.isfinite(e["psnr_db"]), r
base = row("render_march", "(scene)")
assert base["psnr_db"] is not None and 20 < base["psnr_db"] < 120, base
fine, coarse = row("render_march", "march.step=0.25"), row("render_march", "march.step=2")
assert coarse["mean"] > fine["mean"], (coarse, fine)
n2 = row("render_march", "march.light=march march.light_steps=2")
n16 = row("render_march", "march.light=march march.light_steps=16")
assert n16["mean"] < n2["mean"] / 4 and n16["max"] < n2["max"], (n16, n2)
off = row("render_march", "march.skipping.enabled=false")
assert all(off[k] == base[k] for k in ("max", "mean", "p99", "mse")), (off, base)
splat = row("render_splat", "(scene)")
assert splat["count"] == 64 * 48
refs = doc["image_references"]
assert refs and refs[0]["light_rays"] > 0 and refs[0]["step_voxels"] == 0.125, refs
print("image rows ok")
PY]=])
add_test(NAME Cli.AccuracyImages COMMAND /bin/sh -c "${cli_imgacc_accuracy_script}" ${cli} ${cli_out}/imgacc-accuracy
         ${CMAKE_CURRENT_SOURCE_DIR})
set_tests_properties(Cli.AccuracyImages PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION "image rows ok")
# sweep over march.step measures render_march alone (the splat renderer reads no march field and the
# reference ignores the step); two shards merge into the unsharded sweep's rows, PSNR included.
set(cli_imgacc_sweep_script [=[d="$1"; rm -rf "$d"; set -e
s="$2/scenes/imgacc-small.json"
"$0" sweep "$s" --backend cpu --repeat 1 --quiet --vary march.step=0.25,2 --out "$d/whole" >/dev/null
"$0" sweep "$s" --backend cpu --repeat 1 --quiet --vary march.step=0.25,2 --shard 1/2 --out "$d/s1" >/dev/null
"$0" sweep "$s" --backend cpu --repeat 1 --quiet --vary march.step=0.25,2 --shard 2/2 --out "$d/s2" >/dev/null
"$0" merge "$d/s1/sweep.json" "$d/s2/sweep.json" --out "$d/merged" >/dev/null
/usr/bin/python3 - "$d" <<'PY'
import json, os, subprocess, sys
d = sys.argv[1]
whole = json.load(open(d + "/whole/sweep.json"))["rows"]
stages = sorted({r["stage"] for r in whole})
assert stages == ["render_march"], stages
assert len(whole) == 2 and all(list(r["settings"]) == ["march.step"] for r in whole), whole
assert all(r["status"] == "ok" and "psnr_db" in r["error"] for r in whole), whole
merged = json.load(open(d + "/merged/sweep.json"))["rows"]
key = lambda r: (r["stage"], r["settings"].get("march.step"), r["error"]["all"]["max"], r["error"]["psnr_db"])
assert sorted(map(key, whole)) == sorted(map(key, merged)), (whole, merged)
has_mpl = subprocess.run(["/usr/bin/python3", "-c", "import matplotlib"], capture_output=True).returncode == 0
assert not has_mpl or os.path.getsize(d + "/whole/sweep.png") > 0
print("sweep images ok")
PY]=])
add_test(NAME Cli.SweepImages COMMAND /bin/sh -c "${cli_imgacc_sweep_script}" ${cli} ${cli_out}/imgacc-sweep
         ${CMAKE_CURRENT_SOURCE_DIR})
set_tests_properties(Cli.SweepImages PROPERTIES TIMEOUT 120 PASS_REGULAR_EXPRESSION "sweep images ok")
# --reference-step must be a number of voxel edges in [1/1024, 1].
add_test(NAME Cli.AccuracyBadReferenceStepExits2
         COMMAND ${CMAKE_COMMAND} -DCMD=${cli} "-DARGS=accuracy;ci-small;--reference-step;0" -DEXPECT=2
                 ${expect_exit})
set_tests_properties(Cli.AccuracyBadReferenceStepExits2 PROPERTIES PASS_REGULAR_EXPRESSION
                     "--reference-step: needs a number of voxel edges")
# Blender's Cycles as an outside referee (tools/cycles_referee.py; docs/accuracy.md, "Cycles as an outside referee"):
# its single scattering agrees with the exact reference render within the Monte-Carlo noise on cycles-small, and the
# comparison fails when Cycles is given the sun 2 % too strong or the volume half a voxel off (Blender's voxel
# centres uncorrected). Skipped (77) where Debian's blender is not installed.
set(cycles_referee /usr/bin/python3 ${CLOUDBENCH_ROOT}/tools/cycles_referee.py
    ${CMAKE_CURRENT_SOURCE_DIR}/scenes/cycles-small.json --cli ${cli} --bounces 0 --check)
add_test(NAME Cycles.SingleScatteringAgrees COMMAND ${cycles_referee} --out ${cli_out}/cycles)
add_test(NAME Cycles.SunTooStrongDisagrees
         COMMAND ${cycles_referee} --out ${cli_out}/cycles-sun --cycles-param sun_intensity=1.02)
add_test(NAME Cycles.HalfVoxelOffDisagrees
         COMMAND ${cycles_referee} --out ${cli_out}/cycles-offset --samples 64 --set render.width=64
                 --set render.height=48 --cycles-param volume_offset=[0,0,0])
set_tests_properties(Cycles.SingleScatteringAgrees PROPERTIES PASS_REGULAR_EXPRESSION "Single scattering agrees")
set_tests_properties(Cycles.SunTooStrongDisagrees Cycles.HalfVoxelOffDisagrees PROPERTIES
                     PASS_REGULAR_EXPRESSION "Single scattering DISAGREES")
set_tests_properties(Cycles.SingleScatteringAgrees Cycles.SunTooStrongDisagrees Cycles.HalfVoxelOffDisagrees
                     PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300 LABELS slow)
