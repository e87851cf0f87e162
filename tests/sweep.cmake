# sweep's rows, Pareto marks, metrics and exit codes through the CLI (docs/accuracy.md, "Sweeps: which
# rows, the Pareto front and ties"; docs/cli.md). Included from tests/CMakeLists.txt where `cli` and
# `cli_out` are set.
# ci-small over shade.resolution x shadow.form: each stage once per setting of the field it reads (2 rows
# each, not 4), its rows listing that field alone and "any" in the table; exit 0, and report agrees.
set(cli_sweep_rows_script [=[d="$1"; rm -rf "$d"; set -e
"$0" sweep ci-small --backend cpu --steps 4 --repeat 3 --quiet --out "$d" \
  --vary shade.resolution=1,2 --vary shadow.form=beer,thesis > "$d.txt"
"$0" report "$d/sweep.json" -o "$d/report.html" >/dev/null
/usr/bin/python3 - "$d" <<'PY'
import json, sys
d = sys.argv[1]
rows = json.load(open(d + "/sweep.json"))["rows"]
shade = [r for r in rows if r["stage"] == "shade"]
shadow = [r for r in rows if r["stage"] == "shadow"]
assert len(rows) == 4 and len(shade) == 2 and len(shadow) == 2, [(r["stage"], r["settings"]) for r in rows]
assert sorted(r["settings"]["shade.resolution"] for r in shade) == ["1", "2"], shade
assert all(list(r["settings"]) == ["shade.resolution"] for r in shade), shade
assert sorted(r["settings"]["shadow.form"] for r in shadow) == ["beer", "thesis"], shadow
assert all(list(r["settings"]) == ["shadow.form"] for r in shadow), shadow
assert all(r["status"] == "ok" and isinstance(r["pareto_tie"], bool) for r in rows), rows
# The documented rule, worked here: a row is on the front unless another beats it (error at most its own,
# not clearly slower, and clearly faster or smaller in error; clearly: q1-q3 intervals apart).
def beats(o, r):
    lo, lr = o["error"]["all"]["max"], r["error"]["all"]["max"]
    faster = lambda a, b: a["time"]["q3_ms"] < b["time"]["q1_ms"]
    return lo <= lr and not faster(r, o) and (faster(o, r) or lo < lr)
for r in rows:
    assert r["pareto"] == (not any(o is not r and o["stage"] == r["stage"] and beats(o, r) for o in rows)), r
table = open(d + ".txt").read()
assert "| any " in table and "4 stage measurements" in table, table
html = open(d + "/report.html").read()
assert "Verdict: pass (exit code 0)" in html
print("sweep rows: ok")
PY]=])
add_test(NAME Cli.SweepMeasuresEachSettingOnce COMMAND bash -c "${cli_sweep_rows_script}" ${cli}
         ${cli_out}/sweep-rows)
set_tests_properties(Cli.SweepMeasuresEachSettingOnce PROPERTIES TIMEOUT 300 PASS_REGULAR_EXPRESSION "sweep rows: ok")

# On the tiled layers-small, --metric psnr puts the best PSNR on the front. The same sweep.json with every row
# unsupported: report's verdict (html::VerdictOf, the code sweep exits with) is exit code 4, with the rows' reason.
set(cli_sweep_layers_script [=[d="$1"; rm -rf "$d"; mkdir -p "$d"
"$0" sweep layers-small --backend cpu --repeat 3 --reference-step 0.5 --quiet --out "$d/tiled" \
  --vary layers.count=2,8,32 --metric psnr >/dev/null
/usr/bin/python3 - "$d" <<'PY'
import json, math, sys
doc = json.load(open(sys.argv[1] + "/tiled/sweep.json"))
rows = doc["rows"]
assert doc["metric"] == "psnr" and len(rows) == 3, rows
assert all(r["stage"] == "render_layers" and r["status"] == "ok" for r in rows), rows
psnr = lambda r: math.inf if r["error"]["psnr_db"] is None else r["error"]["psnr_db"]
assert all(psnr(r) > 0 for r in rows), rows
# Nothing has a higher PSNR than the best row, so nothing beats it: it is on the front.
assert max(rows, key=psnr)["pareto"], rows
for r in rows:
    r["status"], r["detail"] = "unsupported", "a stand-in reason"
json.dump(doc, open(sys.argv[1] + "/none.json", "w"))
PY
"$0" report "$d/none.json" -o "$d/none.html" >/dev/null
grep -q "Verdict: fail (exit code 4)" "$d/none.html" || { echo "report: no exit code 4"; exit 1; }
grep -q "a stand-in reason" "$d/none.html" || { echo "report: no reason"; exit 1; }
echo "sweep layers: ok"
]=])
add_test(NAME Cli.SweepNothingMeasuredExits4AsReport COMMAND bash -c "${cli_sweep_layers_script}" ${cli}
         ${cli_out}/sweep-layers)
set_tests_properties(Cli.SweepNothingMeasuredExits4AsReport PROPERTIES TIMEOUT 300
                     PASS_REGULAR_EXPRESSION "sweep layers: ok")

# Refused before anything runs (exit 2): PSNR for a volume stage, an unknown metric, fields no stage reads.
add_test(NAME Cli.SweepPsnrRefusedForShade COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=sweep;ci-small;--vary;shade.resolution=1,2;--metric;psnr;--out;${cli_out}/sweep-refused" -DEXPECT=2
         -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
set_tests_properties(Cli.SweepPsnrRefusedForShade PROPERTIES PASS_REGULAR_EXPRESSION
                     "--metric psnr: PSNR is defined for the renderers' images only.*shade \\(shade.resolution\\)")
add_test(NAME Cli.SweepUnknownMetricExits2 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=sweep;ci-small;--vary;shade.resolution=1,2;--metric;rmse;--out;${cli_out}/sweep-refused" -DEXPECT=2
         -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
set_tests_properties(Cli.SweepUnknownMetricExits2 PROPERTIES PASS_REGULAR_EXPRESSION
                     "--metric: must be max, mean, p99 or psnr, got 'rmse'")
add_test(NAME Cli.SweepFieldNoStageReadsExits2 COMMAND ${CMAKE_COMMAND} -DCMD=${cli}
         "-DARGS=sweep;ci-small;--vary;description=a,b;--out;${cli_out}/sweep-refused" -DEXPECT=2
         -P ${CMAKE_CURRENT_SOURCE_DIR}/expect_exit.cmake)
set_tests_properties(Cli.SweepFieldNoStageReadsExits2 PROPERTIES PASS_REGULAR_EXPRESSION
                     "no measured stage .* reads description")
