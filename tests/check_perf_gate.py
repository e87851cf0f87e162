#!/usr/bin/python3
"""The CI performance gate on this machine, as docs/cli.md ("In CI") runs it:
`perf compare --interleave --clock cpu` of one build with itself passes (exit
0), and the same build with a slowdown planted in one stage through the
test-only CLOUDBENCH_TEST_SLOWDOWN switch fails with the regression exit code
6, naming that stage and no other, whatever else the machine runs (CTest runs
it beside other tests).

usage: check_perf_gate.py CLOUDBENCH WORKDIR identical|slowdown
"""
import json
import os
import shutil
import stat
import subprocess
import sys

CLI, WORK, CASE = os.path.abspath(sys.argv[1]), sys.argv[2], sys.argv[3]
# ci-small on the CPU: region takes about 0.13 ms; x2 adds as much again. The rounds are perf compare's own
# choice (checked below).
PLANTED_STAGE, PLANTED_FACTOR = "region", 2

shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
head = CLI
if CASE == "slowdown":
    # HEAD is the same binary with the planted slowdown: a wrapper that sets the switch.
    head = os.path.join(WORK, "slow-cloudbench")
    with open(head, "w") as f:
        f.write(f'#!/bin/sh\nCLOUDBENCH_TEST_SLOWDOWN={PLANTED_STAGE}:{PLANTED_FACTOR} exec "{CLI}" "$@"\n')
    os.chmod(head, os.stat(head).st_mode | stat.S_IXUSR)
p = subprocess.run([CLI, "perf", "compare", "--interleave", CLI, head, "ci-small", "--backend", "cpu",
                    "--clock", "cpu", "--quiet", "--json", os.path.join(WORK, "compare.json")],
                   capture_output=True, text=True, timeout=600)
print(p.stdout)
doc = json.load(open(os.path.join(WORK, "compare.json")))
regressions = [c["stage"] for c in doc["comparisons"] if c["regression"]]
if CASE == "identical":
    if p.returncode != 0 or regressions:
        print(f"FAIL: identical builds: exit {p.returncode}, regressions {regressions}\n{p.stderr}")
        sys.exit(1)
else:
    if p.returncode != 6 or regressions != [PLANTED_STAGE] or f"ci-small/cpu/{PLANTED_STAGE}" not in p.stdout:
        print(f"FAIL: planted {PLANTED_STAGE} x{PLANTED_FACTOR}: exit {p.returncode}, regressions {regressions}\n"
              f"{p.stderr}")
        sys.exit(1)
if doc["clock"] != "cpu":
    print(f"FAIL: the gate compares CPU time, the JSON says {doc['clock']}")
    sys.exit(1)
if doc["mode"].startswith("interleaved") is False or doc["separate"]:
    print("FAIL: an interleaved comparison must say so and use the interleaved threshold")
    sys.exit(1)
# The rounds perf compare chose: the smallest K at which a slowdown with two rounds against it still reaches
# alpha after Holm over the m time comparisons, m (1 + K + K(K-1)/2) 2^-K < alpha (docs/cli.md, "Rounds").
m = sum(1 for c in doc["comparisons"] if c["metric"] == "time")
rounds = next(k for k in range(1, 100) if m * (1 + k + k * (k - 1) / 2) * 2.0 ** -k < doc["alpha"])
if f"{rounds} rounds" not in doc["mode"]:
    print(f"FAIL: {m} comparisons need {rounds} rounds; perf compare ran: {doc['mode']}")
    sys.exit(1)
unjudged = [c["stage"] for c in doc["comparisons"] if c["mark"] == "?"]
if unjudged or any(c["test"] != "rounds" for c in doc["comparisons"] if c["metric"] == "time"):
    print(f"FAIL: every stage must be judged over the rounds; not judged: {unjudged}")
    sys.exit(1)
print(f"perf gate {CASE}: ok")
