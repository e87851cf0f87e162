#!/usr/bin/python3
"""The CI performance gate on this machine, as docs/cli.md ("In CI") runs it:
`perf compare --interleave --clock cpu` of one build with itself passes (exit
0), and the same build with a slowdown planted in one stage (`--plant
STAGE:FACTOR`, which sets the test-only CLOUDBENCH_TEST_SLOWDOWN switch in
HEAD's runs and its factor-1 control in BASE's) fails with the regression exit
code 6, naming that stage and no other, whatever else the machine runs (CTest
runs it beside other tests). The HTML report of the slowdown's --json file and
of its kept folder shows that stage marked + and the verdict's exit code 6.

The gate's alpha is 0.01 for users: with no change, a comparison is flagged
with probability at most 0.01, so a test that asserted 'identical builds pass'
at that alpha would fail one run in a hundred by design. These tests give
`--alpha 0.0001` (25 rounds instead of 17 for ci-small's 7 stages): the same
rules, with a false alarm once in ten thousand runs at most.

The case `kept` checks that a verdict never improves on a second look: a
short real interleave whose BASE runs exit 1 ends with exit 1 live and again
from its kept folder (`perf compare DIR`), both naming each failed run; so
does a kept run recorded as failed with no folder, and a kept folder cut short
(fewer runs than its rounds); a kept folder with no run is refused (exit 3).

usage: check_perf_gate.py CLOUDBENCH WORKDIR identical|slowdown|kept
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


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def wrapper(name, body):
    """An executable script in WORK that runs the CLI under test as `body` says."""
    path = os.path.join(WORK, name)
    with open(path, "w") as f:
        f.write(f"#!/bin/sh\n{body}\n")
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path


def compare(*args):
    return subprocess.run([CLI, "perf", "compare", *args], capture_output=True, text=True, timeout=600)


def failed_run_lines(stderr):
    return sorted(line for line in stderr.splitlines() if line.startswith("perf compare: failed run: "))


def check_kept():
    # Two rounds of ci-small, 4 steps: about a second. BASE writes its results and exits 1.
    failing = wrapper("failing-cloudbench", f'"{CLI}" "$@"\nexit 1')
    fast = ["ci-small", "--rounds", "2", "--steps", "4", "--set", "warmup_steps=1", "--backend", "cpu", "--quiet"]
    kept = os.path.join(WORK, "kept")
    live = compare("--interleave", failing, CLI, *fast, "--keep", kept, "--json", os.path.join(WORK, "live.json"))
    again = compare(kept, "--json", os.path.join(WORK, "again.json"))
    expected = [f"perf compare: failed run: base run of ci-small in round {r} exited 1" for r in (1, 2)]
    for what, p, path in (("live", live, "live.json"), ("from the kept folder", again, "again.json")):
        if p.returncode != 1 or failed_run_lines(p.stderr) != expected:
            fail(f"BASE runs exited 1: {what}: exit {p.returncode} (expected 1), failed runs "
                 f"{failed_run_lines(p.stderr)}\n{p.stdout}\n{p.stderr}")
        doc = json.load(open(os.path.join(WORK, path)))
        runs = [(r["side"], r["scene"], r["round"], r["exit"], r["compared"]) for r in doc["failed_runs"]]
        if doc["exit_code"] != 1 or runs != [("base", "ci-small", 0, 1, True), ("base", "ci-small", 1, 1, True)]:
            fail(f"{what}: the JSON's exit_code {doc['exit_code']} and failed_runs {runs}")
        if "no regression\n" in p.stdout:
            fail(f"{what}: a failed run must not end with a plain 'no regression':\n{p.stdout}")

    # A clean kept interleave passes; one run recorded as failed, with no folder, is named and exits 1.
    clean = os.path.join(WORK, "clean")
    p = compare("--interleave", CLI, CLI, *fast, "--keep", clean)
    q = compare(clean)
    if p.returncode != q.returncode or failed_run_lines(q.stderr):
        fail(f"a clean interleave: live exit {p.returncode}, from the kept folder {q.returncode}\n{q.stderr}")
    manifest_path = os.path.join(clean, "interleave.json")
    manifest = json.load(open(manifest_path))
    first = manifest["runs"][0]
    shutil.rmtree(os.path.join(clean, first["folder"]))
    manifest["runs"][0]["exit"] = 1
    json.dump(manifest, open(manifest_path, "w"))
    q = compare(clean)
    line = (f"perf compare: failed run: {first['side']} run of ci-small in round 1 exited 1 "
            "and wrote no valid results.json")
    if q.returncode != 1 or failed_run_lines(q.stderr) != [line]:
        fail(f"a kept run recorded as exit 1 without its folder: exit {q.returncode}\n{q.stderr}")

    # A kept folder cut short (the last run missing) never passes: the live command it came from gave no verdict.
    shutil.rmtree(clean)
    compare("--interleave", CLI, CLI, *fast, "--keep", clean)
    manifest = json.load(open(manifest_path))
    manifest["runs"] = manifest["runs"][:-1]
    json.dump(manifest, open(manifest_path, "w"))
    q = compare(clean)
    if q.returncode != 1 or "the interleave was cut short: 3 of 4 runs recorded" not in q.stderr:
        fail(f"a kept interleave cut short: exit {q.returncode}\n{q.stderr}")

    # No run recorded: refused as a bad input file, naming the file and the field.
    manifest["runs"] = []
    json.dump(manifest, open(manifest_path, "w"))
    q = compare(clean)
    if q.returncode != 3 or f"{manifest_path}: /runs: no run was recorded; nothing to compare" not in q.stderr:
        fail(f"a kept interleave with no run: exit {q.returncode}\n{q.stderr}")
    print("perf gate kept: ok")


if CASE == "kept":
    check_kept()
    sys.exit(0)

plant = []
if CASE == "slowdown":
    # HEAD is the same binary with the planted slowdown; --plant gives BASE its control, the switch with factor 1,
    # which spins for no time but wakes the arena's threads as HEAD's spin does (docs/cli.md), in an environment
    # of the same length, so that the two sides differ in the planted spin's length alone. With BASE the bare
    # binary, HEAD also differed in its environment (one variable more moves the stack and heap of every stage)
    # and in the wake of the workers before the planted stage: systematic differences outside it, which 17 rounds
    # can resolve (render_splat flagged at 1.104x in one of nine suite runs; with a control that did not wake the
    # workers, density, a 9 us stage, at 1.101x in one of seven runs under load 5).
    plant = ["--plant", f"{PLANTED_STAGE}:{PLANTED_FACTOR}"]
GATE_ALPHA = 1e-4
kept = os.path.join(WORK, "kept")
p = subprocess.run([CLI, "perf", "compare", "--interleave", CLI, CLI, "ci-small", "--backend", "cpu",
                    "--clock", "cpu", "--alpha", str(GATE_ALPHA), "--quiet", "--keep", kept,
                    "--json", os.path.join(WORK, "compare.json"), *plant],
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
if doc["alpha"] != GATE_ALPHA:
    print(f"FAIL: --alpha {GATE_ALPHA} given, the JSON says {doc['alpha']}")
    sys.exit(1)
if doc["mode"].startswith("interleaved (random order)") is False or doc["separate"]:
    print("FAIL: an interleaved comparison must say so and use the interleaved threshold")
    sys.exit(1)
# The rounds perf compare chose: the smallest K at which a slowdown with two rounds against it still reaches
# alpha after Holm over the m time comparisons, m (1 + K + K(K-1)/2) 2^-K < alpha (docs/cli.md, "Rounds").
m = sum(1 for c in doc["comparisons"] if c["metric"] == "time")
rounds = next(k for k in range(1, 100) if m * (1 + k + k * (k - 1) / 2) * 2.0 ** -k < doc["alpha"])
if f"{rounds} rounds" not in doc["mode"]:
    print(f"FAIL: {m} comparisons need {rounds} rounds; perf compare ran: {doc['mode']}")
    sys.exit(1)
# Each round's order is a fair coin: across the rounds both orders occur and the pattern is not ABBA's
# alternation (a fair coin gives one of those three patterns with probability 3 x 2^-25).
manifest = json.load(open(os.path.join(kept, "interleave.json")))
first = [run["side"] for n, run in enumerate(manifest["runs"]) if n % 2 == 0]
abba = ["base" if r % 2 == 0 else "head" for r in range(len(first))]
if manifest["order"] != "random" or len(set(first)) != 2 or first == abba:
    print(f"FAIL: the order within each round must be drawn at random: order {manifest['order']}, "
          f"first run of each round {first}")
    sys.exit(1)
unjudged = [c["stage"] for c in doc["comparisons"] if c["mark"] == "?"]
if unjudged or any(c["test"] != "rounds" for c in doc["comparisons"] if c["metric"] == "time"):
    print(f"FAIL: every stage must be judged over the rounds; not judged: {unjudged}")
    sys.exit(1)
if CASE == "slowdown":
    # The plant is kept in interleave.json and in the verdict, and the HTML report of the --json file and of the
    # kept folder (its compare.json) shows the planted stage marked + and the verdict's exit code 6.
    planted = {"stage": PLANTED_STAGE, "factor": PLANTED_FACTOR}
    if manifest.get("plant") != planted or doc.get("plant") != planted:
        print(f"FAIL: --plant: interleave.json's plant {manifest.get('plant')}, the JSON's {doc.get('plant')}")
        sys.exit(1)
    for source in (os.path.join(WORK, "compare.json"), kept):
        page_path = os.path.join(WORK, "report.html")
        r = subprocess.run([CLI, "report", source, "-o", page_path], capture_output=True, text=True, timeout=120)
        page = open(page_path).read() if r.returncode == 0 else ""
        # A row of the comparison table: its mark, then scene, backend and stage.
        row = f"<tr><td>+</td><td>ci-small</td><td>cpu</td><td>{PLANTED_STAGE}</td><td>time</td>"
        flagged = [line for line in page.splitlines() if line.startswith("<tr><td>+</td>")]
        if r.returncode != 0 or len(flagged) != 1 or not flagged[0].startswith(row) or \
                f"Verdict: regression: ci-small/cpu/{PLANTED_STAGE} (x" not in page or "(exit code 6).</p>" not in page:
            print(f"FAIL: report {source}: exit {r.returncode}; the page must mark {PLANTED_STAGE} alone with + and "
                  f"give exit code 6; rows marked +: {flagged}\n{r.stderr}")
            sys.exit(1)
    # --junit on the kept folder: a test case per time and count comparison, the planted stage the one failure,
    # read back by Debian's python3-junitparser where it is installed.
    junit = os.path.join(WORK, "compare.xml")
    r = compare(kept, "--junit", junit)
    try:
        from junitparser import Failure, JUnitXml
    except ImportError:
        JUnitXml = None
    if r.returncode != 6:
        print(f"FAIL: perf compare {kept} --junit: exit {r.returncode}\n{r.stderr}")
        sys.exit(1)
    if JUnitXml is not None:
        suite = next(iter(JUnitXml.fromfile(junit)))
        failed = [(c.classname, c.name, c.result[0].message) for c in suite
                  if any(isinstance(x, Failure) for x in c.result)]
        if suite.tests != len(doc["comparisons"]) or len(failed) != 1 or failed[0][:2] != ("ci-small.cpu",
                                                                                              PLANTED_STAGE) or \
                "threshold" not in failed[0][2]:
            print(f"FAIL: --junit: {suite.tests} cases for {len(doc['comparisons'])} comparisons, failures {failed}")
            sys.exit(1)
print(f"perf gate {CASE}: ok")
