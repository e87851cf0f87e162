#!/usr/bin/python3
"""sweep --shard I/N and cloudbench merge (docs/cli.md): N shards run as
separate processes and merged give the unsharded sweep's table; histories
merge with each record once; a shard set with an index missing is refused.
Usage: check_shard.py CLOUDBENCH OUTDIR"""
import json
import os
import shutil
import subprocess
import sys

cli, out = sys.argv[1], sys.argv[2]
shutil.rmtree(out, ignore_errors=True)
os.makedirs(out)
SWEEP = ["sweep", "ci-small", "--backend", "cpu", "--steps", "12", "--repeat", "1",
         "--vary", "shade.sigma=0.5,1,2", "--quiet"]  # sigma: both shade and shadow are measured
SHARDS = 2


def run(args, expect=0):
    p = subprocess.run([cli] + args, capture_output=True, text=True, timeout=900)
    if p.returncode != expect:
        sys.exit(f"FAIL: {' '.join(args)}: exit {p.returncode}, expected {expect}\n{p.stdout}\n{p.stderr}")
    return p


def rows(path):
    with open(path) as f:
        return json.load(f)["rows"]


# The fields a rerun reproduces. The times are measured afresh in every process
# and differ from run to run; the Pareto marks follow from the times, so they
# differ too (merge recomputes them over all rows; that is checked below).
def deterministic(row):
    return {k: v for k, v in row.items() if k not in ("time", "pareto", "pareto_tie")}


run(SWEEP + ["--out", f"{out}/whole"])
shard_files = []
for i in range(1, SHARDS + 1):
    run(SWEEP + ["--shard", f"{i}/{SHARDS}", "--out", f"{out}/shard{i}"])
    shard_files.append(f"{out}/shard{i}/sweep.json")
# Shard 1 of 2 holds points 0 and 2 (k % 2 == 0): sigma 0.5 and 2.
with open(shard_files[0]) as f:
    shard1 = json.load(f)["shard"]
assert (shard1["index"], shard1["count"], shard1["points"]) == (1, 2, 3), shard1
assert sorted({r["point"] for r in shard1["rows"]}) == [0, 2], shard1["rows"]
assert {r["settings"][0][1] for r in shard1["rows"]} == {"0.5", "2"}, shard1["rows"]

# Given in reverse order: merge orders by shard index and point, not by argument.
run(["merge"] + shard_files[::-1] + ["--out", f"{out}/merged"])
whole, merged = rows(f"{out}/whole/sweep.json"), rows(f"{out}/merged/sweep.json")
if [deterministic(r) for r in whole] != [deterministic(r) for r in merged]:
    sys.exit("FAIL: merged rows differ from the unsharded sweep:\n" +
             json.dumps([deterministic(r) for r in whole], indent=1) + "\n" +
             json.dumps([deterministic(r) for r in merged], indent=1))
assert len(whole) == 6, whole  # 3 points x 2 stages (shade, shadow) x cpu
assert [r["stage"] for r in whole] == ["shade"] * 3 + ["shadow"] * 3, whole  # by stage, then point
# The merged Pareto front is recomputed over all rows: per stage, a row is
# marked exactly when no other ok row beats it (docs/accuracy.md: error at most
# its own, not clearly slower, and clearly faster or smaller in error, where
# clearly faster means the q1-q3 time intervals are apart).
def beats(o, r):
    lo, lr = o["error"]["all"]["max"], r["error"]["all"]["max"]
    faster = lambda a, b: a["time"]["q3_ms"] < b["time"]["q1_ms"]
    return lo <= lr and not faster(r, o) and (faster(o, r) or lo < lr)


for r in merged:
    if r["status"] != "ok":
        continue
    beaten = any(o is not r and o["stage"] == r["stage"] and o["status"] == "ok" and beats(o, r) for o in merged)
    assert r["pareto"] == (not beaten), r
assert os.path.exists(f"{out}/merged/sweep.md")

# A shard set with index 2 missing (2 of 3 given twice would be the other case).
p = run(["merge", shard_files[0], "--out", f"{out}/bad"], expect=3)
assert "/shard/index" in p.stderr and "missing" in p.stderr, p.stderr
p = run(["merge", shard_files[0], shard_files[0], "--out", f"{out}/bad"], expect=3)
assert "/shard/index" in p.stderr, p.stderr

# Histories from two machines, one record in both; a half-written last line in one.
def record(rid, time):
    return json.dumps({"format": "cloudbench-perf/1", "id": rid, "time": time, "results": {}})

with open(f"{out}/a.jsonl", "w") as f:
    f.write(record("20260101T120000Z-aaaaaa", "2026-01-01T12:00:00Z") + "\n")
    f.write(record("20260103T120000Z-cccccc", "2026-01-03T12:00:00Z") + "\n")
with open(f"{out}/b.jsonl", "w") as f:
    f.write(record("20260102T120000Z-bbbbbb", "2026-01-02T12:00:00Z") + "\n")
    f.write(record("20260103T120000Z-cccccc", "2026-01-03T12:00:00Z") + "\n")
    f.write(record("20260104T120000Z-dddddd", "2026-01-04T12:00:00Z")[:30])
p = run(["merge", f"{out}/a.jsonl", f"{out}/b.jsonl", "--out", f"{out}/hist"])
assert "b.jsonl:3" in p.stderr, p.stderr
with open(f"{out}/hist/history.jsonl") as f:
    ids = [json.loads(line)["id"] for line in f]
assert ids == ["20260101T120000Z-aaaaaa", "20260102T120000Z-bbbbbb", "20260103T120000Z-cccccc"], ids

# Sweeps and histories mixed: a usage error.
run(["merge", shard_files[0], f"{out}/a.jsonl", "--out", f"{out}/bad"], expect=2)
print("shard and merge: ok")
