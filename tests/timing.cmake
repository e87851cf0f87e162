# The two ways to time a step (docs/performance.md, "Two ways to time a step") through the CLI.
# Included from tests/CMakeLists.txt where `cli`, `cli_out` and `expect_exit` are set.
#
# ci-small on every built backend (exit 4, no GPU backend here: the others still run), 8 steps of which 2 warm-up,
# under --timing pipelined and --timing both. results.json's "timing" names the mode; pipelined, every step after
# warm-up opened one batch, a stage's call time is "host" (never "wall") and the thesis's per-stage fields hold no
# sample; both: steps 3, 4, 7 synchronized and 2, 5, 6 pipelined (S P P S from step 0), and a pipelined step waits no more often than a
# synchronized one. The CPU has no device: it counts nothing.
set(cli_timing_script [=[d="$1"; rm -rf "$d"; mkdir -p "$d"; set -e
for mode in pipelined both synchronized; do
  "$0" run ci-small --quiet --out "$d/$mode" --timing $mode --set steps=8 --set warmup_steps=2 \
    --set render.every_steps=1 >"$d/$mode.txt" || test $? -eq 4
done
/usr/bin/python3 - "$d" <<'PY'
import json, sys
d = sys.argv[1]
runs = {m: json.load(open(f"{d}/{m}/results.json")) for m in ("pipelined", "both", "synchronized")}
ok = [n for n, b in runs["both"]["backends"].items() if b["status"] == "ok"]
assert "cpu" in ok, runs["both"]["backends"].keys()
for name in ok:
    p = runs["pipelined"]["backends"][name]
    t = p["timing"]
    assert t["mode"] == "pipelined" and "synchronized" not in t, (name, t.keys())
    tp = t["pipelined"]
    assert tp["steps"] == 6 and tp["batches"] == {"median": 1, "min": 1, "max": 1}, (name, tp["steps"], tp["batches"])
    for stage, s in tp["stages"].items():
        assert "wall" not in s and s["host"]["count"] > 0, (name, stage, s)
        assert p["stages"][stage]["count"] == 0, (name, stage, "no synchronized sample")
    assert p["stage_runs"]["region"]["ran"] == 8 and p["loop"]["steps"] == 6, (name, p["stage_runs"], p["loop"])
    b = runs["both"]["backends"][name]
    tb = b["timing"]
    assert tb["mode"] == "both" and tb["synchronized"]["steps"] == 3 and tb["pipelined"]["steps"] == 3, (name, tb)
    assert b["stages"]["region"]["count"] == 3, (name, b["stages"]["region"])
    assert tb["pipelined"]["host_waits"]["median"] <= tb["synchronized"]["host_waits"]["median"], (name, tb)
    s = runs["synchronized"]["backends"][name]["timing"]
    assert s["mode"] == "synchronized" and "pipelined" not in s and s["synchronized"]["steps"] == 6, (name, s)
    if name == "vk":
        # The batch's one wait and render_splat's one read-back of its splat and pair totals for ci-small's one
        # camera (docs/performance.md, "vk render_splat: pairs sorted by tile"); 3 while it read back twice.
        assert tp["host_waits"]["max"] <= 2, (name, tp["host_waits"])
    if name == "cpu":
        for mode in ("synchronized", "pipelined"):
            assert tb[mode]["submissions"] == {"median": 0, "min": 0, "max": 0}, (mode, tb[mode])
    print(name, "pipelined", tp["submissions"]["median"], "submissions,", tp["host_waits"]["median"], "waits;",
          "synchronized", s["synchronized"]["submissions"]["median"], "submissions,",
          s["synchronized"]["host_waits"]["median"], "waits")
print("timing checked")
PY
grep -q "pipelined: step .* submission.*; synchronized: step " "$d/both.txt"
# The CPU computes the same frames in every mode: the EXRs are equal byte for byte but for the date they were written
# (OpenImageIO's capDate), and so are the top views.
/usr/bin/python3 - "$d" <<'PY'
import re, sys
d = sys.argv[1]
def exr(mode):
    return re.sub(rb"capDate\0string\0....\d{4}:\d\d:\d\d \d\d:\d\d:\d\d", b"", open(f"{d}/{mode}/frame-splat-above-cpu.exr", "rb").read(), flags=re.S)
for mode in ("pipelined", "both"):
    assert exr(mode) == exr("synchronized"), mode
    assert open(f"{d}/{mode}/topview-cpu.png", "rb").read() == open(f"{d}/synchronized/topview-cpu.png", "rb").read(), mode
print("frames identical")
PY]=])
add_test(NAME Cli.TimingModes COMMAND /bin/sh -c "${cli_timing_script}" ${cli} ${cli_out}/timing)
set_tests_properties(Cli.TimingModes PROPERTIES TIMEOUT 300 PASS_REGULAR_EXPRESSION "timing checked.*frames identical")

# A --timing that is not a mode: exit 2 before any work, the modes named.
add_test(NAME Cli.TimingBadValueExits2 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=run;ci-small;--timing;pipelining;--quiet;--out;${cli_out}/timing-usage" -DEXPECT=2 ${expect_exit})
set_tests_properties(Cli.TimingBadValueExits2 PROPERTIES PASS_REGULAR_EXPRESSION
  "exit code 2 as expected. stderr: cloudbench: --timing: must be synchronized, pipelined or both \\(got 'pipelining'\\)")
