#!/usr/bin/python3
"""`cloudbench perf record`: each record is one JSON line
appended to the history with the documented shape (docs/results.md); earlier
lines are never rewritten; a line cut short is skipped with a warning naming
the file and line, and the next record still starts a line of its own; a
`count` output's "instructions" are merged in; each stage keeps its CPU times
beside its wall times, run by run, so `--clock cpu` compares records, and a
record without them (written before) is refused on that clock, naming it.

usage: check_perf_record.py CLOUDBENCH WORKDIR
"""
import json
import os
import shutil
import subprocess
import sys

import numpy as np

CLI, WORK = sys.argv[1], sys.argv[2]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
history = os.path.join(WORK, "sub", "history.jsonl")  # the folder is created by the first record
suite = os.path.join(WORK, "suite.json")
json.dump({"scenes": [{"scene": "ci-small", "set": ["steps=16", "warmup_steps=4"]}]}, open(suite, "w"))
counts = os.path.join(WORK, "counts.json")
json.dump({"instructions": {"ci-small": {"cpu": {"region": 123456, "ca": 654321}}}}, open(counts, "w"))


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def record(*extra, expect=0):
    p = subprocess.run([CLI, "perf", "record", "--suite", suite, "--history", history, "--backend", "cpu", "--quiet",
                        *extra], capture_output=True, text=True, timeout=300)
    if p.returncode != expect:
        fail(f"perf record exited {p.returncode}, expected {expect}\n{p.stdout}\n{p.stderr}")
    return p


record("--instructions", counts, "--repeat", "2")
first = open(history, "rb").read()
lines = first.decode().splitlines()
if len(lines) != 1:
    fail(f"one record must be one line, got {len(lines)}")
r = json.loads(lines[0])
for key in ("format", "id", "time", "provenance", "suite", "results", "failures", "instructions", "seconds"):
    if key not in r:
        fail(f"record lacks '{key}'")
if r["format"] != "cloudbench-perf/1":
    fail(f"format {r['format']}")
for key in ("git", "build", "machine"):
    if key not in r["provenance"]:
        fail(f"provenance lacks '{key}'")
stages = r["results"]["ci-small"]["cpu"]
# 16 steps, 4 of warm-up: 12 samples a run, two runs pooled (--repeat 2).
for name in ("region", "ca", "smooth", "density"):
    samples = stages[name]["samples_ms"]
    if len(samples) != 24:
        fail(f"{name}: {len(samples)} samples, expected 2 x 12")
    if abs(stages[name]["median_ms"] - float(np.median(samples))) > 1e-12:
        fail(f"{name}: median_ms is not the median of samples_ms")
    # Each run's samples apart too, in the order pooled, so that perf compare can test over the runs.
    runs = stages[name].get("runs_ms")
    if runs is None or [len(x) for x in runs] != [12, 12] or runs[0] + runs[1] != samples:
        fail(f"{name}: runs_ms must hold the two runs' 12 samples each, pooled in samples_ms: {runs}")
    # The same runs' CPU times beside them (results.json's "cpu"), run by run.
    cpu = stages[name].get("cpu")
    if cpu is None or [len(x) for x in cpu.get("runs_ms", [])] != [12, 12] or \
            cpu["runs_ms"][0] + cpu["runs_ms"][1] != cpu["samples_ms"] or \
            abs(cpu["median_ms"] - float(np.median(cpu["samples_ms"]))) > 1e-12:
        fail(f"{name}: cpu must hold the two runs' 12 CPU times each, pooled, and their median: {cpu}")
if r["instructions"] != {"ci-small": {"cpu": {"region": 123456, "ca": 654321}}}:
    fail(f"instructions not merged: {r['instructions']}")

# A write cut short (no newline), then another record.
with open(history, "ab") as f:
    f.write(b'{"format": "cloudbench-perf/1", "id": "cut')
record()
data = open(history, "rb").read()
if not data.startswith(first):
    fail("an earlier record was rewritten")
lines = data.decode().splitlines()
if len(lines) != 3 or json.loads(lines[2])["format"] != "cloudbench-perf/1":
    fail(f"the new record must start a line of its own after the cut line: {len(lines)} lines")
p = subprocess.run([CLI, "perf", "compare", f"{history}@-2", f"{history}@-1"], capture_output=True, text=True,
                   timeout=120)
if p.returncode not in (0, 6) or f"{history}:2: skipped" not in p.stderr:
    fail(f"compare of the two records: exit {p.returncode}, stderr {p.stderr!r}")
if "different times" not in p.stdout:
    fail("two records are measured at different times: the output must say so")

# Records compare on the CPU clock; one written before records kept CPU times is refused there, named.
p = subprocess.run([CLI, "perf", "compare", f"{history}@-2", f"{history}@-1", "--clock", "cpu"], capture_output=True,
                   text=True, timeout=120)
if p.returncode not in (0, 6) or "clock" not in p.stdout or "cpu" not in p.stdout:
    fail(f"compare --clock cpu of two records: exit {p.returncode}\n{p.stdout}\n{p.stderr}")
old = json.loads(lines[2])
for entry in old["results"]["ci-small"]["cpu"].values():
    entry.pop("cpu", None)
old_history = os.path.join(WORK, "old.jsonl")
open(old_history, "w").write(lines[0] + "\n" + json.dumps(old) + "\n")
p = subprocess.run([CLI, "perf", "compare", f"{old_history}@-2", f"{old_history}@-1", "--clock", "cpu"],
                   capture_output=True, text=True, timeout=120)
if p.returncode != 3 or f"{old_history}@{old['id']} (line 2)" not in p.stderr or '"cpu"' not in p.stderr:
    fail(f"--clock cpu on a record without CPU times must exit 3 naming it: {p.returncode} {p.stderr!r}")
p = subprocess.run([CLI, "perf", "history", old_history, "--clock", "cpu"], capture_output=True, text=True,
                   timeout=120)
if p.returncode != 3 or f"{old_history}:2: record {old['id']}" not in p.stderr:
    fail(f"history --clock cpu on a record without CPU times must exit 3 naming it: {p.returncode} {p.stderr!r}")
# Without --clock, a history with such a record is searched on wall time, and says why.
p = subprocess.run([CLI, "perf", "history", old_history], capture_output=True, text=True, timeout=120)
if p.returncode != 0 or "clock wall" not in p.stdout or old["id"] not in p.stdout:
    fail(f"history of a record without CPU times: exit {p.returncode}, wall clock naming it\n{p.stdout}{p.stderr}")

# A bad suite file is a bad input (exit 3) and appends nothing.
json.dump({"scenes": []}, open(suite, "w"))
p = record(expect=3)
if "scenes" not in p.stderr or open(history, "rb").read() != data:
    fail(f"bad suite: {p.stderr}")
print("perf record: ok")
