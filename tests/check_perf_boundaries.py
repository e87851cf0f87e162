#!/usr/bin/python3
"""`perf compare`'s decision rules at their boundaries, through the command (docs/cli.md, "perf compare"):

rounds: how many rounds `--interleave` runs without --rounds: the smallest K with
  m x (1 + K + K(K-1)/2) x 2^-K < alpha (m the time comparisons of the first round). With alpha set to exactly
  m x (1 + K + K(K-1)/2) x 2^-K (a dyadic fraction, so exact in binary), K is not enough and K + 1 rounds run; with
  alpha one ulp above it, K rounds run. The children are a stand-in `cloudbench run` written here that writes a
  results.json of m stages, so no real measurement is involved and the count is deterministic.
unjudged: a kept interleave of two stages and 7 rounds, every round 1.5x slower: 2^-7 < 0.01 but 2 x 2^-7 >=
  0.01, so neither can be judged: marked ?, named in the warning and in --json's `unjudged`, exit 0. At
  --alpha 0.015625 (= 2 x 2^-7) still ?; one ulp above, both are regressions, exit 6, and `unjudged` is empty.
  One stage 2x faster alone: -, exit 0.

usage: check_perf_boundaries.py CLOUDBENCH WORKDIR rounds|unjudged
"""
import json
import math
import os
import shutil
import stat
import subprocess
import sys

CLI, WORK, CASE = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2]), sys.argv[3]
STAGES = ["region", "ca", "smooth", "density", "shade", "shadow", "render_splat"]


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def run(*args, expect):
    p = subprocess.run([CLI, "perf", "compare", *args], capture_output=True, text=True, timeout=300)
    if p.returncode != expect:
        fail(f"perf compare {' '.join(args)}: exit {p.returncode}, expected {expect}\n{p.stdout}\n{p.stderr}")
    return p


def results(path, times):
    """A results.json of stage -> samples (ms) on the cpu backend, wall clock."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    doc = {"format": "cloudbench-results/1", "scene": {"name": "s"},
           "backends": {"cpu": {"status": "ok", "stages": {k: {"samples_ms": v} for k, v in times.items()}}}}
    with open(path, "w") as f:
        json.dump(doc, f)


def rounds_needed(m, alpha):
    """The rule as docs/cli.md states it."""
    return next(k for k in range(1, 200) if m * (1 + k + k * (k - 1) / 2) * 2.0 ** -k < alpha)


def case_rounds():
    # `FAKE run SCENE --out OUT --quiet`: SCENE is "mN", the first N stages, each 20 steps of 1 ms.
    fake = os.path.join(WORK, "fake-cloudbench")
    with open(fake, "w") as f:
        f.write(f"""#!/usr/bin/python3
import json, os, sys
scene, out = sys.argv[2], sys.argv[sys.argv.index("--out") + 1]
os.makedirs(out, exist_ok=True)
stages = {STAGES!r}[:int(scene[1:])]
doc = {{"format": "cloudbench-results/1", "scene": {{"name": scene}},
       "backends": {{"cpu": {{"status": "ok", "stages": {{k: {{"samples_ms": [1.0] * 20}} for k in stages}}}}}}}}
json.dump(doc, open(os.path.join(out, "results.json"), "w"))
""")
    os.chmod(fake, os.stat(fake).st_mode | stat.S_IXUSR)

    def chosen(m, alpha):
        out = os.path.join(WORK, "r.json")
        run("--interleave", fake, fake, f"m{m}", "--alpha", repr(alpha), "--quiet", "--json", out, expect=0)
        doc = json.load(open(out))
        n = sum(1 for c in doc["comparisons"] if c["metric"] == "time")
        if n != m:
            fail(f"m{m}: {n} comparisons")
        return int(doc["mode"].split(", ")[1].split()[0])

    for m, k in ((1, 10), (3, 12), (7, 16)):
        at = m * (1 + k + k * (k - 1) // 2) / 2.0 ** k  # exact: a small integer over a power of two
        if at * 2.0 ** k != m * (1 + k + k * (k - 1) // 2):
            fail(f"{at} is not exact")
        for alpha, expected in ((at, k + 1), (math.nextafter(at, 1.0), k)):
            if rounds_needed(m, alpha) != expected:
                fail(f"the oracle: m {m}, alpha {alpha!r}: {rounds_needed(m, alpha)} rounds, expected {expected}")
            got = chosen(m, alpha)
            if got != expected:
                fail(f"{m} comparisons at alpha {alpha!r} (= {m} x {1 + k + k * (k - 1) // 2} x 2^-{k}"
                     f"{'' if alpha == at else ' + 1 ulp'}): {got} rounds, expected {expected}")
    # The default alpha: 17 rounds for one scene of 7 stages (docs/cli.md).
    if chosen(7, 0.01) != 17:
        fail("7 comparisons at alpha 0.01 must take 17 rounds")
    print("perf boundaries rounds: ok")


def kept(folder, rounds, stages):
    """A kept interleave: stage -> head/base ratio, one step of 1 ms in BASE each round."""
    shutil.rmtree(folder, ignore_errors=True)
    runs = []
    for k in range(rounds):
        for side in (("base", "head") if k % 2 == 0 else ("head", "base")):
            name = f"{side}/r{k + 1:02d}-s"
            results(f"{folder}/{name}/results.json",
                    {st: [1.0 * (ratio if side == "head" else 1.0)] for st, ratio in stages.items()})
            runs.append({"side": side, "scene": "s", "round": k, "folder": name, "exit": 0, "load": [1, 1, 1]})
    with open(f"{folder}/interleave.json", "w") as f:
        json.dump({"format": "cloudbench-interleave/1", "base": "a", "head": "b", "scenes": ["s"],
                   "rounds": rounds, "order": "ABBA", "runs": runs}, f)


def case_unjudged():
    folder, out = os.path.join(WORK, "two"), os.path.join(WORK, "two.json")
    kept(folder, 7, {"region": 1.5, "ca": 1.5})
    for alpha, code in (("0.01", 0), ("0.015625", 0), (repr(math.nextafter(0.015625, 1.0)), 6)):
        p = run(folder, "--alpha", alpha, "--json", out, expect=code)
        doc = json.load(open(out))
        marks = {c["stage"]: c["mark"] for c in doc["comparisons"]}
        if code == 0:
            if marks != {"region": "?", "ca": "?"} or sorted(doc["unjudged"]) != ["s/cpu/ca", "s/cpu/region"]:
                fail(f"alpha {alpha}: 2 x 2^-7 >= alpha: both '?' and unjudged; marks {marks}, "
                     f"unjudged {doc['unjudged']}")
            if "warning: 2 of 2 time comparisons could not be judged (marked ?): s/cpu/ca s/cpu/region" not in p.stdout:
                fail(f"alpha {alpha}: the warning must name both:\n{p.stdout}")
            if doc["regressions"] != 0 or doc["exit_code"] != 0:
                fail(f"alpha {alpha}: an inconclusive result passes: {doc['regressions']}, {doc['exit_code']}")
        else:
            if marks != {"region": "+", "ca": "+"} or doc["unjudged"] != [] or doc["exit_code"] != 6:
                fail(f"alpha {alpha}: both judged regressions: marks {marks}, unjudged {doc['unjudged']}")
            for c in doc["comparisons"]:
                if c["p_slower"] != 2.0 ** -7 or c["p_slower_holm"] != 2 * 2.0 ** -7:
                    fail(f"alpha {alpha}: p {c['p_slower']}, Holm {c['p_slower_holm']}: expected 2^-7 and 2^-6")
            if "regression: s/cpu/ca (x1.50) s/cpu/region (x1.50)" not in p.stdout:
                fail(f"the regression line must name both:\n{p.stdout}")
    # One stage, 8 rounds 2x faster: 2^-8 < 0.01, an improvement, exit 0.
    kept(folder, 8, {"region": 0.5})
    run(folder, "--json", out, expect=0)
    doc = json.load(open(out))
    if [c["mark"] for c in doc["comparisons"]] != ["-"] or doc["unjudged"]:
        fail(f"a judged improvement: {doc['comparisons']}")
    print("perf boundaries unjudged: ok")


if __name__ == "__main__":
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    {"rounds": case_rounds, "unjudged": case_unjudged}[CASE]()
