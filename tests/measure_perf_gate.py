#!/usr/bin/python3
"""Measures the wall-time gate of `perf compare --interleave` (issue 12, item
9): the false-alarm rate over N comparisons of one build with itself, and how
often a slowdown planted with CLOUDBENCH_TEST_SLOWDOWN=<stage>:<factor> is
caught. Not a CTest test (minutes); its numbers go to reports/perf/walltime.md.

usage: measure_perf_gate.py CLOUDBENCH WORKDIR identical N BACKENDS ROUNDS
       measure_perf_gate.py CLOUDBENCH WORKDIR separate N BACKENDS ROUNDS
         (N + 1 back-to-back runs, each pair of neighbours compared as two files: not interleaved)
       measure_perf_gate.py CLOUDBENCH WORKDIR slowdown N BACKENDS ROUNDS STAGE FACTOR...
The scene is ci-small, or $PERF_SCENE with the extra run options in $PERF_EXTRA (e.g. "--steps 120").
Prints one line per comparison and a summary; every comparison's JSON is kept in WORKDIR.
"""
import json
import os
import stat
import subprocess
import sys
import time

CLI, WORK, CASE, N, BACKENDS, ROUNDS = os.path.abspath(sys.argv[1]), sys.argv[2], sys.argv[3], int(sys.argv[4]), \
    sys.argv[5], sys.argv[6]
os.makedirs(WORK, exist_ok=True)
SCENE = os.environ.get("PERF_SCENE", "ci-small")
EXTRA = os.environ.get("PERF_EXTRA", "").split()


def compare(head, tag):
    out = os.path.join(WORK, f"{tag}.json")
    start = time.time()
    p = subprocess.run([CLI, "perf", "compare", "--interleave", CLI, head, SCENE, "--backend", BACKENDS,
                        "--rounds", ROUNDS, "--quiet", "--json", out, *EXTRA], capture_output=True, text=True)
    doc = json.load(open(out))
    rows = [c for c in doc["comparisons"] if c["p_slower_holm"] is not None]
    return p.returncode, doc, rows, time.time() - start


def wrapper(stage, factor):
    path = os.path.join(WORK, f"slow-{stage}-{factor}")
    with open(path, "w") as f:
        f.write(f'#!/bin/sh\nCLOUDBENCH_TEST_SLOWDOWN={stage}:{factor} exec "{CLI}" "$@"\n')
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path


if CASE == "identical":
    alarms, significant, ratios, seconds = 0, 0, [], []
    for n in range(N):
        code, doc, rows, s = compare(CLI, f"identical-{n}")
        seconds.append(s)
        alarms += code == 6
        sig = [r for r in rows if r["p_slower_holm"] < doc["alpha"] or r["p_faster_holm"] < doc["alpha"]]
        significant += len(sig)
        ratios += [r["ratio"] for r in rows]
        worst = max(rows, key=lambda r: abs(r["ratio"] - 1))
        listed = ", ".join("%s/%s x%.2f" % (r["backend"], r["stage"], r["ratio"]) for r in sig)
        print(f"{n}: exit {code}, {len(rows)} tested, {len(sig)} significant "
              f"({listed}), "
              f"widest {worst['backend']}/{worst['stage']} x{worst['ratio']:.2f}, {s:.0f} s", flush=True)
    tested = len(ratios)
    print(f"SUMMARY identical: {alarms} of {N} comparisons exit 6; {significant} of {tested} stage comparisons "
          f"significant (Holm, alpha 0.01); ratios {min(ratios):.3f}..{max(ratios):.3f}; "
          f"median {sorted(seconds)[len(seconds) // 2]:.1f} s a comparison")
elif CASE == "separate":
    for n in range(N + 1):
        subprocess.run([CLI, "run", SCENE, *EXTRA, "--backend", BACKENDS, "--quiet", "--out", os.path.join(WORK, f"run{n}")],
                       capture_output=True, check=True)
    alarms, ratios, named = 0, [], []
    for n in range(N):
        out = os.path.join(WORK, f"separate-{n}.json")
        p = subprocess.run([CLI, "perf", "compare", os.path.join(WORK, f"run{n}", "results.json"),
                            os.path.join(WORK, f"run{n + 1}", "results.json"), "--json", out], capture_output=True,
                           text=True)
        doc = json.load(open(out))
        rows = [c for c in doc["comparisons"] if c["p_slower_holm"] is not None]
        ratios += [r["ratio"] for r in rows]
        flagged = ["%s/%s x%.2f" % (c["backend"], c["stage"], c["ratio"]) for c in doc["comparisons"] if c["regression"]]
        alarms += p.returncode == 6
        named += flagged
        print(f"{n}: exit {p.returncode}, regressions {flagged}", flush=True)
    print(f"SUMMARY separate: {alarms} of {N} comparisons exit 6 (threshold {doc['threshold']}); "
          f"tested ratios {min(ratios):.3f}..{max(ratios):.3f}; flagged {named}")
else:
    stage, factors = sys.argv[7], sys.argv[8:]
    for factor in factors:
        head = wrapper(stage, factor)
        caught, others, ratios = 0, 0, []
        for n in range(N):
            code, doc, rows, s = compare(head, f"slow-{stage}-{factor}-{n}")
            named = [f"{r['backend']}/{r['stage']}" for r in doc["comparisons"] if r["regression"]]
            hit = [r for r in doc["comparisons"] if r["stage"] == stage and r["backend"] == "cpu"][0]
            caught += hit["regression"]
            others += len([x for x in named if not x.endswith("/" + stage)])
            ratios.append(hit["ratio"])
            print(f"{stage} x{factor} #{n}: exit {code}, regressions {named}, ratio {hit['ratio']:.2f} "
                  f"p {hit['p_slower_holm']:.2g}", flush=True)
        print(f"SUMMARY slowdown {stage} x{factor}: caught {caught} of {N}; other stages flagged {others}; "
              f"measured ratios {min(ratios):.2f}..{max(ratios):.2f}")
