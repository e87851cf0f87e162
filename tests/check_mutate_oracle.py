#!/usr/bin/python3
"""Checks which tests tools/mutate.py's CTest oracle runs with its default options, in a configured build
folder (docs/testing.md, "What the ctest oracle leaves out"):

- every GoogleTest case of the unit-test binary is in it, the regression gate's statistics (PerfStats.*,
  PerfGateBoundary.*) among them;
- what it leaves out is one of the slow groups, named here by hand: the sanitized build (Sanitized.*), the fuzz
  run (Fuzz.*), exact mode's build and counts (Exact.*), the benchmarks (Bench.*), Blender's Cycles renders
  (Cycles.*), and Tools.MutantsApply, which fails in every mutated tree by construction;
- every test of the sanitized build, the fuzz run and the benchmarks is left out.

usage: check_mutate_oracle.py MUTATE_PY BUILD_DIR
"""
import json
import subprocess
import sys

SLOW_GROUPS = ("Sanitized.", "Fuzz.", "Exact.", "Bench.", "Cycles.")
ALWAYS_OUT = ("Sanitized.", "Fuzz.", "Bench.")


def main():
    mutate, build = sys.argv[1], sys.argv[2]
    shown = subprocess.run(["ctest", "--test-dir", build, "--show-only=json-v1"], capture_output=True, text=True,
                           check=True)
    tests = json.loads(shown.stdout)["tests"]
    every = {t["name"] for t in tests}
    unit = {t["name"] for t in tests if t.get("command") and t["command"][0].endswith("/cloudbench_tests")}
    listed = subprocess.run([sys.executable, mutate, "--list-ctest-oracle", "--build-dir", build],
                            capture_output=True, text=True)
    if listed.returncode != 0:
        print("FAIL: mutate.py --list-ctest-oracle exited %d: %s" % (listed.returncode, listed.stderr.strip()))
        sys.exit(1)
    oracle = set(line for line in listed.stdout.splitlines() if line)
    problems = []
    if not unit:
        problems.append("no GoogleTest case found in %s: the check proves nothing" % build)
    if not any(n.startswith("PerfStats.") for n in unit):
        problems.append("no PerfStats.* case registered: the check proves nothing")
    if oracle - every:
        problems.append("the oracle lists tests CTest does not have: %s" % sorted(oracle - every)[:5])
    missing = sorted(unit - oracle)
    if missing:
        problems.append("%d unit tests are not in the oracle, e.g. %s" % (len(missing), missing[:5]))
    out = every - oracle
    unexpected = sorted(n for n in out if not n.startswith(SLOW_GROUPS) and n != "Tools.MutantsApply")
    if unexpected:
        problems.append("%d tests outside the slow groups are left out, e.g. %s" % (len(unexpected), unexpected[:5]))
    kept = sorted(n for n in oracle if n.startswith(ALWAYS_OUT))
    if kept:
        problems.append("slow tests in the oracle: %s" % kept[:5])
    if "Tools.MutantsApply" in oracle:
        problems.append("Tools.MutantsApply is in the oracle")
    for p in problems:
        print("FAIL: " + p)
    if problems:
        sys.exit(1)
    print("the ctest oracle runs %d of %d tests, every one of the %d unit tests; left out: %s" %
          (len(oracle), len(every), len(unit), ", ".join(sorted({n.split(".")[0] + ".*" for n in out}))))


if __name__ == "__main__":
    main()
