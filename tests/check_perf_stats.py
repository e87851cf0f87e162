#!/usr/bin/python3
"""Checks `cloudbench perf compare`, `perf history` and `perf export` against
independent oracles: SciPy for the permutation tests over rounds and runs, the
Mann-Whitney U p-values and the bootstrap intervals, NumPy for the medians and
quantiles, Holm's step-down written here from its definition, the marks and
exit codes from the documented rule (docs/cli.md). The samples are made here
with a fixed seed; no expected number comes from cloudbench's own output.

usage: check_perf_stats.py CLOUDBENCH WORKDIR CASE
CASE: compare, rounds, clock, runs, instructions, inputs, history, changepoints, verdicts, gbench
"""
import json
import os
import shutil
import subprocess
import sys
import zlib

import numpy as np
from scipy import stats

CLI, WORK, CASE = sys.argv[1], sys.argv[2], sys.argv[3]
# The defaults of perf compare (docs/cli.md).
ALPHA, FLOOR_MS, SEPARATE_THRESHOLD = 0.01, 0.05, 2.0


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)


def close(a, b, rel, what):
    check(abs(a - b) <= rel * max(abs(a), abs(b)), f"{what}: {a!r} vs {b!r} (relative tolerance {rel})")


def results_json(path, scene, stages, backend="cpu", status="ok", commit="0" * 40, date="2026-01-01T00:00:00Z",
                 cpu=None):
    """cpu: {stage: samples} of the process's CPU time beside the wall times, for the stages it names."""
    entries = {name: {"samples_ms": [float(v) for v in samples]} for name, samples in stages.items()}
    for name, samples in (cpu or {}).items():
        entries[name]["cpu"] = {"samples_ms": [float(v) for v in samples]}
    doc = {"format": "cloudbench-results/1", "scene": {"name": scene},
           "backends": {backend: {"status": status, "stages": entries}},
           "provenance": {"git": {"commit": commit, "dirty": False}, "date": date}}
    with open(path, "w") as f:
        json.dump(doc, f)


def run(*args, expect=None):
    p = subprocess.run([CLI, *args], capture_output=True, text=True, timeout=300)
    if expect is not None and p.returncode != expect:
        fail(f"{' '.join(args)}: exit {p.returncode}, expected {expect}\n{p.stdout}\n{p.stderr}")
    return p


def holm(p):
    """Holm's step-down adjusted p-values, from the definition."""
    m = len(p)
    order = sorted(range(m), key=lambda i: p[i])
    adjusted, running = [0.0] * m, 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[i]))
        adjusted[i] = running
    return adjusted


def case_compare():
    rng = np.random.RandomState(7)
    # Stage -> (base, head): sizes differ, values rounded to make ties, shifts from none to large.
    def lognormal(n, median, spread):
        return np.round(median * np.exp(rng.normal(0, spread, n)), 3)
    # Stage names are real ones: a results.json naming an unknown stage is refused (docs/cli.md#input-files).
    stages = {
        "region":       (lognormal(60, 1.0, 0.1), lognormal(45, 1.0, 0.1)),   # the same
        "ca":           (lognormal(40, 1.0, 0.1), lognormal(50, 3.0, 0.1)),   # 3x slower
        "smooth":       (lognormal(80, 1.0, 0.05), lognormal(80, 1.3, 0.05)),  # significant, within the threshold
        "density":      (lognormal(30, 2.0, 0.1), lognormal(30, 0.6, 0.1)),   # 3x faster
        "shade":        (lognormal(40, 0.01, 0.1), lognormal(40, 0.03, 0.1)),  # 3x slower, under the 0.05 ms floor
        "shadow":       (np.round(rng.normal(5, 0.5, 50), 0), np.round(rng.normal(5.3, 0.5, 50), 0)),  # ties
        "render_splat": (lognormal(5, 1.0, 0.1), lognormal(5, 9.0, 0.1)),  # too few samples: never a regression
    }
    results_json(f"{WORK}/base.json", "s", {k: v[0] for k, v in stages.items()}, date="2026-01-01T00:00:00Z")
    results_json(f"{WORK}/head.json", "s", {k: v[1] for k, v in stages.items()}, date="2026-01-02T00:00:00Z")
    p = run("perf", "compare", f"{WORK}/base.json", f"{WORK}/head.json", "--json", f"{WORK}/cmp.json",
            expect=6)
    check("different times" in p.stdout, "a comparison of two files must say they were measured at different times")
    doc = json.load(open(f"{WORK}/cmp.json"))
    check(doc["threshold"] == SEPARATE_THRESHOLD, "separate files must use the wider threshold")
    rows = {c["stage"]: c for c in doc["comparisons"]}
    check(set(rows) == set(stages), f"stages compared: {sorted(rows)}")
    tested = [k for k in sorted(stages) if len(stages[k][0]) >= 20 and len(stages[k][1]) >= 20]
    slower = {k: stats.mannwhitneyu(stages[k][1], stages[k][0], alternative="greater", method="asymptotic").pvalue
              for k in tested}
    faster = {k: stats.mannwhitneyu(stages[k][1], stages[k][0], alternative="less", method="asymptotic").pvalue
              for k in tested}
    slower_holm = dict(zip(tested, holm([slower[k] for k in tested])))
    faster_holm = dict(zip(tested, holm([faster[k] for k in tested])))
    for k, (base, head) in stages.items():
        c = rows[k]
        close(c["base_median"], float(np.median(base)), 1e-12, f"{k} base median")
        close(c["head_median"], float(np.median(head)), 1e-12, f"{k} head median")
        close(c["ratio"], float(np.median(head) / np.median(base)), 1e-12, f"{k} ratio")
        check(c["test"] == "steps", f"{k}: one run a side must be tested on its steps: {c['test']}")
        if k not in tested:
            check(c["mark"] == "?" and not c["regression"] and c["p_slower"] is None, f"{k}: too few samples: {c}")
            continue
        close(c["p_slower"], slower[k], 1e-9, f"{k} p slower")
        close(c["p_faster"], faster[k], 1e-9, f"{k} p faster")
        close(c["p_slower_holm"], slower_holm[k], 1e-9, f"{k} Holm p slower")
        close(c["p_faster_holm"], faster_holm[k], 1e-9, f"{k} Holm p faster")
        # The percentile bootstrap of the ratio of medians, each side resampled on its own.
        ci = stats.bootstrap((base, head), lambda b, h, axis: np.median(h, axis=axis) / np.median(b, axis=axis),
                             method="percentile", n_resamples=20000, random_state=1, vectorized=True,
                             confidence_level=0.95).confidence_interval
        # Two Monte Carlo estimates of one quantile: they agree to the spacing of the bootstrap distribution.
        close(c["ratio_ci"][0], ci.low, 0.03, f"{k} interval low")
        close(c["ratio_ci"][1], ci.high, 0.03, f"{k} interval high")
        ratio, difference = np.median(head) / np.median(base), np.median(head) - np.median(base)
        regression = slower_holm[k] < ALPHA and ratio > SEPARATE_THRESHOLD and difference > FLOOR_MS
        improvement = faster_holm[k] < ALPHA and ratio < 1 / SEPARATE_THRESHOLD and -difference > FLOOR_MS
        expected = "+" if regression else "-" if improvement else "~"
        check(c["mark"] == expected and c["regression"] == regression, f"{k}: mark {c['mark']}, expected {expected}")
    check(rows["ca"]["regression"] and rows["density"]["mark"] == "-", "the planted changes must be found")
    check(not rows["shade"]["regression"] and not rows["smooth"]["regression"], "floor and threshold must hold")
    check("s/cpu/ca" in p.stdout, "the regression line must name the stage")
    # gl and vk have their own default threshold, 3x (software drivers); --threshold gl=R sets gl's.
    gl_base, gl_head = lognormal(40, 1.0, 0.05), lognormal(40, 2.5, 0.05)
    results_json(f"{WORK}/gl-base.json", "s", {"region": gl_base}, backend="gl")
    results_json(f"{WORK}/gl-head.json", "s", {"region": gl_head}, backend="gl")
    run("perf", "compare", f"{WORK}/gl-base.json", f"{WORK}/gl-head.json", "--json", f"{WORK}/gl.json", expect=0)
    check(json.load(open(f"{WORK}/gl.json"))["comparisons"][0]["threshold"] == 3.0, "gl's default threshold is 3")
    run("perf", "compare", f"{WORK}/gl-base.json", f"{WORK}/gl-head.json", "--threshold", "gl=2", "--json",
        f"{WORK}/gl.json", expect=6)
    check(json.load(open(f"{WORK}/gl.json"))["comparisons"][0]["threshold"] == 2.0, "--threshold gl=2")
    run("perf", "compare", f"{WORK}/gl-base.json", f"{WORK}/gl-head.json", "--threshold", "=2", expect=2)
    # A stage that cannot be judged is named in a warning and in the JSON.
    check("warning: 1 of 7 time comparisons could not be judged (marked ?): s/cpu/render_splat" in p.stdout,
          f"the unjudged stage must be warned about: {p.stdout}")
    check(doc["unjudged"] == ["s/cpu/render_splat"], f"unjudged: {doc['unjudged']}")
    # A file compared with itself: no regression, and a warning.
    p = run("perf", "compare", f"{WORK}/base.json", f"{WORK}/base.json", expect=0)
    check("BASE and HEAD are the same file" in p.stderr, f"comparing a file with itself must warn: {p.stderr}")
    # The folder a `run --out` wrote is read as its results.json.
    os.makedirs(f"{WORK}/run-folder", exist_ok=True)
    shutil.copy(f"{WORK}/base.json", f"{WORK}/run-folder/results.json")
    run("perf", "compare", f"{WORK}/run-folder", f"{WORK}/base.json", expect=0)
    os.makedirs(f"{WORK}/empty-folder", exist_ok=True)
    p = run("perf", "compare", f"{WORK}/empty-folder", f"{WORK}/base.json", expect=3)
    check("empty-folder: is a folder without a results.json" in p.stderr, f"a folder without results: {p.stderr}")
    # HEAD failed: marked x, exit 1 (no regression to report).
    results_json(f"{WORK}/failed.json", "s", {}, status="crashed")
    p = run("perf", "compare", f"{WORK}/base.json", f"{WORK}/failed.json", expect=1)
    check(p.stdout.count("| x ") == len(stages), "every stage of a crashed HEAD must be marked x")
    # New in HEAD: marked !.
    p = run("perf", "compare", f"{WORK}/failed.json", f"{WORK}/base.json", expect=0)
    check(p.stdout.count("| ! ") == len(stages), "every stage absent from BASE must be marked !")
    print("perf compare: ok")


def kept_interleave(folder, scene, rounds, cpu_rounds=None, load=1):
    """A kept interleave written by hand: rounds[k] = {stage: (base samples, head samples)}, ABBA order;
    cpu_rounds[k] the same for the CPU times; every run started at load average `load`."""
    shutil.rmtree(folder, ignore_errors=True)
    runs = []
    for k, stages in enumerate(rounds):
        for side in (("base", "head") if k % 2 == 0 else ("head", "base")):
            name = f"{side}/r{k + 1:02d}-{scene}"
            os.makedirs(f"{folder}/{name}")
            n = 0 if side == "base" else 1
            results_json(f"{folder}/{name}/results.json", scene, {st: v[n] for st, v in stages.items()},
                         cpu={st: v[n] for st, v in cpu_rounds[k].items()} if cpu_rounds else None)
            runs.append({"side": side, "scene": scene, "round": k, "folder": name, "exit": 0,
                         "load": [load, load, load]})
    with open(f"{folder}/interleave.json", "w") as f:
        json.dump({"format": "cloudbench-interleave/1", "base": "a", "head": "b", "scenes": [scene],
                   "rounds": len(rounds), "order": "ABBA", "runs": runs}, f)


def sign_flip_p(d):
    """SciPy's exact paired permutation test (the signs flipped) that mean(d) > 0."""
    return stats.permutation_test((d,), np.mean, permutation_type="samples", alternative="greater",
                                  n_resamples=np.inf).pvalue


def case_rounds():
    rng = np.random.RandomState(11)
    K = 10
    # Per round and stage: each run's steps. "smooth" is 1.25x slower in every round; "region" has two modes
    # (a free or a busy second core: 0.7 or 1.3 ms) mixed differently in each run, with no change; "ca" is
    # 1.05x slower (significant, within the 1.1 threshold); "density" is 1.3x faster.
    def steps(n, median, spread=0.02):
        return np.round(median * np.exp(rng.normal(0, spread, n)), 5)
    def modal(n):
        busy = rng.rand() < 0.5
        return np.round(np.where(rng.rand(n) < (0.8 if busy else 0.2), 1.3, 0.7) * np.exp(rng.normal(0, 0.02, n)), 5)
    rounds = []
    for k in range(K):
        load = np.exp(rng.normal(0, 0.05))  # the round's machine speed, shared by both of its runs
        rounds.append({"smooth": (steps(30, 1.0 * load), steps(30, 1.25 * load)),
                       "region": (modal(30), modal(30)),
                       "ca": (steps(30, 2.0 * load), steps(30, 2.1 * load)),
                       "density": (steps(30, 0.5 * load), steps(30, 0.5 / 1.3 * load)),
                       "shade": (steps(3, 2.0 * load, 0.2), steps(3, 2.0 * load, 0.2))})
    kept = f"{WORK}/kept"
    kept_interleave(kept, "s", rounds)
    p = run("perf", "compare", kept, "--json", f"{WORK}/rounds.json", expect=6)
    doc = json.load(open(f"{WORK}/rounds.json"))
    rows = {c["stage"]: c for c in doc["comparisons"]}
    names = sorted(rows)
    d = {st: np.array([np.log(np.median(r[st][1]) / np.median(r[st][0])) for r in rounds]) for st in names}
    slower = [sign_flip_p(d[st]) for st in names]
    faster = [sign_flip_p(-d[st]) for st in names]
    slower_holm, faster_holm = dict(zip(names, holm(slower))), dict(zip(names, holm(faster)))
    for i, st in enumerate(names):
        c = rows[st]
        check(c["test"] == "rounds" and c["pairs"] == K, f"{st}: paired by round: {c['test']}, {c['pairs']}")
        close(c["ratio"], float(np.exp(d[st].mean())), 1e-9, f"{st} ratio")
        close(c["p_slower"], slower[i], 1e-9, f"{st} p slower")
        close(c["p_faster"], faster[i], 1e-9, f"{st} p faster")
        close(c["p_slower_holm"], slower_holm[st], 1e-9, f"{st} Holm p slower")
        ci = stats.bootstrap((d[st],), lambda x, axis: np.exp(np.mean(x, axis=axis)), method="percentile",
                             n_resamples=20000, random_state=1, confidence_level=0.95).confidence_interval
        close(c["ratio_ci"][0], ci.low, 0.02, f"{st} interval low")
        close(c["ratio_ci"][1], ci.high, 0.02, f"{st} interval high")
        ratio = np.exp(d[st].mean())
        expected = "+" if slower_holm[st] < ALPHA and ratio > 1.1 else \
            "-" if faster_holm[st] < ALPHA and ratio < 1 / 1.1 else "~"
        check(c["mark"] == expected, f"{st}: mark {c['mark']}, expected {expected}")
    check([c["stage"] for c in doc["comparisons"] if c["regression"]] == ["smooth"],
          f"only smooth is slower: {[(c['stage'], c['mark']) for c in doc['comparisons']]}")
    check(rows["density"]["mark"] == "-" and rows["region"]["mark"] == "~", "density faster, region unchanged")
    check("interleaved (ABBA), 10 rounds, kept in" in p.stdout, f"the mode line: {p.stdout}")
    # Steps pooled over the runs, as a Mann-Whitney test takes them, make region's two modes a large
    # difference whenever the mixes differ; the rounds do not.
    check(rows["region"]["p_slower"] > 0.01 and rows["region"]["p_faster"] > 0.01, f"region: {rows['region']}")
    # --run-quantile: another statistic of each run's steps.
    run("perf", "compare", kept, "--run-quantile", "0.25", "--json", f"{WORK}/q25.json", expect=6)
    q = {c["stage"]: c for c in json.load(open(f"{WORK}/q25.json"))["comparisons"]}
    d25 = np.array([np.log(np.quantile(r["smooth"][1], 0.25) / np.quantile(r["smooth"][0], 0.25)) for r in rounds])
    close(q["smooth"]["ratio"], float(np.exp(d25.mean())), 1e-9, "smooth ratio of 25th percentiles")
    # Four rounds cannot reach p < 0.01 over five tests (5 x 2^-4 = 0.31): every stage is '?', with a warning.
    kept_interleave(f"{WORK}/kept4", "s", rounds[:4])
    p = run("perf", "compare", f"{WORK}/kept4", "--json", f"{WORK}/rounds4.json", expect=0)
    doc = json.load(open(f"{WORK}/rounds4.json"))
    check(all(c["mark"] == "?" for c in doc["comparisons"]) and len(doc["unjudged"]) == 5,
          f"4 rounds: {[(c['stage'], c['mark']) for c in doc['comparisons']]}")
    check("warning: 5 of 5 time comparisons could not be judged" in p.stdout, p.stdout)
    # A run's folder must be its side's and one name deep: nothing outside the kept folder is read.
    manifest = json.load(open(f"{kept}/interleave.json"))
    manifest["runs"][0]["folder"] = "base/../../elsewhere"
    with open(f"{kept}/interleave.json", "w") as f:
        json.dump(manifest, f)
    p = run("perf", "compare", kept, expect=3)
    check("/runs/0/folder: must be base/NAME" in p.stderr, f"a folder outside the kept one: {p.stderr}")
    print("perf compare rounds: ok")


def case_clock():
    rng = np.random.RandomState(17)
    K = 12
    # A loaded machine: each run's wall times sit in one of two modes (the second core free or taken), and
    # its CPU times do not. "region" does 1.3x the work in HEAD: its CPU time shows it in every round, its
    # wall time is buried under the modes. "ca" waits longer in HEAD (wall 1.5x) at the same CPU time.
    def steps(n, median, spread=0.02):
        return np.round(median * np.exp(rng.normal(0, spread, n)), 5)
    wall, cpu = [], []
    for k in range(K):
        mode = [1.0 if rng.rand() < 0.5 else 1.9 for _ in range(2)]  # each run's share of a core
        wall.append({"region": (steps(30, 1.0 * mode[0]), steps(30, 1.3 * mode[1])),
                     "ca": (steps(30, 2.0), steps(30, 3.0))})
        cpu.append({"region": (steps(30, 1.9), steps(30, 1.9 * 1.3)), "ca": (steps(30, 3.8), steps(30, 3.8))})
    kept = f"{WORK}/kept-clock"
    kept_interleave(kept, "s", wall, cpu, load=9)
    for clock, rounds, slower in (("cpu", cpu, "region"), ("wall", wall, "ca")):
        p = run("perf", "compare", kept, "--clock", clock, "--json", f"{WORK}/{clock}.json", expect=6)
        doc = json.load(open(f"{WORK}/{clock}.json"))
        check(doc["clock"] == clock, f"--clock {clock}: the JSON says {doc['clock']}")
        check(f"clock: {clock}" in p.stdout, f"--clock {clock}: the header must say it: {p.stdout}")
        rows = {c["stage"]: c for c in doc["comparisons"]}
        names = sorted(rows)
        d = {st: np.array([np.log(np.median(r[st][1]) / np.median(r[st][0])) for r in rounds]) for st in names}
        holm_p = dict(zip(names, holm([sign_flip_p(d[st]) for st in names])))
        for st in names:
            close(rows[st]["ratio"], float(np.exp(d[st].mean())), 1e-9, f"--clock {clock}: {st} ratio")
            close(rows[st]["p_slower_holm"], holm_p[st], 1e-9, f"--clock {clock}: {st} Holm p")
        check([c["stage"] for c in doc["comparisons"] if c["regression"]] == [slower],
              f"--clock {clock}: only {slower} is slower: {[(c['stage'], c['mark']) for c in doc['comparisons']]}")
        # Runs that started at load 9 on this machine's cores: wall times get a warning, CPU times need none.
        loaded = "warning: the machine was loaded" in p.stdout
        check(loaded == (clock == "wall" and os.cpu_count() < 9), f"--clock {clock}: the load warning: {p.stdout}")
    # Results without CPU times (written before cloudbench measured them) cannot be compared on it.
    results_json(f"{WORK}/old.json", "s", {"region": [1.0] * 20})
    p = run("perf", "compare", f"{WORK}/old.json", f"{WORK}/old.json", "--clock", "cpu", expect=3)
    check("old.json: /backends/cpu/stages/region: has no \"cpu\" time" in p.stderr, p.stderr)
    # A record written before perf record kept CPU times is refused on the CPU clock, named with its line.
    with open(f"{WORK}/h.jsonl", "w") as f:
        f.write(json.dumps(record("r1", "1" * 40, {"region": 1.0})) + "\n")
    p = run("perf", "compare", f"{WORK}/h.jsonl", f"{WORK}/old.json", "--clock", "cpu", expect=3)
    check("h.jsonl@r1 (line 1): /results/s/cpu/region: has no \"cpu\" time" in p.stderr, p.stderr)
    # Records with CPU times compare on them: the same wall times, CPU times twice as long in HEAD.
    rng = np.random.RandomState(11)
    with open(f"{WORK}/hc.jsonl", "w") as f:
        for rid, cpu_ms in (("c1", 2.0), ("c2", 4.0)):
            r = record(rid, "1" * 40, {"region": 1.0})
            entry = r["results"]["s"]["cpu"]["region"]
            samples = list(np.round(cpu_ms * np.exp(rng.normal(0, 0.05, 30)), 4))
            entry["cpu"] = {"samples_ms": samples, "median_ms": float(np.median(samples))}
            f.write(json.dumps(r) + "\n")
    for clock, ratio in (("cpu", 2.0), ("wall", 1.0)):
        p = run("perf", "compare", f"{WORK}/hc.jsonl@c1", f"{WORK}/hc.jsonl@c2", "--clock", clock, "--json",
                f"{WORK}/hc-{clock}.json")
        row = json.load(open(f"{WORK}/hc-{clock}.json"))["comparisons"][0]
        close(row["ratio"], ratio, 0.1, f"records on --clock {clock}")
    p = run("perf", "compare", f"{WORK}/old.json", f"{WORK}/old.json", "--clock", "device", expect=2)
    check("--clock: needs wall or cpu, got 'device'" in p.stderr + p.stdout, p.stderr)
    print("perf compare clock: ok")


def case_runs():
    rng = np.random.RandomState(13)
    # Two history records of several runs each ("runs_ms", as perf record --repeat writes), not interleaved:
    # a two-sample permutation test over the runs' log medians.
    def runs(n, median, spread):
        return [list(np.round(median * np.exp(rng.normal(0, spread)) * np.exp(rng.normal(0, 0.02, 20)), 5))
                for _ in range(n)]
    sides = {"base": {"region": runs(5, 1.0, 0.05), "ca": runs(5, 1.0, 0.05)},
             "head": {"region": runs(6, 1.0, 0.05), "ca": runs(6, 2.6, 0.05)}}
    path = f"{WORK}/runs.jsonl"
    with open(path, "w") as f:
        for rid, side in (("r1", "base"), ("r2", "head")):
            results = {"s": {"cpu": {st: {"samples_ms": [v for r in rs for v in r], "runs_ms": rs}
                                     for st, rs in sides[side].items()}}}
            f.write(json.dumps({"format": "cloudbench-perf/1", "id": rid, "results": results}) + "\n")
    p = run("perf", "compare", f"{path}@r1", f"{path}@r2", "--json", f"{WORK}/runs.json", expect=6)
    rows = {c["stage"]: c for c in json.load(open(f"{WORK}/runs.json"))["comparisons"]}
    logs = {side: {st: np.log([np.median(r) for r in rs]) for st, rs in v.items()} for side, v in sides.items()}
    names = sorted(rows)
    slower = [stats.permutation_test((logs["head"][st], logs["base"][st]), lambda x, y: np.mean(x) - np.mean(y),
                                     permutation_type="independent", alternative="greater",
                                     n_resamples=np.inf).pvalue for st in names]
    slower_holm = dict(zip(names, holm(slower)))
    for i, st in enumerate(names):
        c = rows[st]
        check(c["test"] == "runs" and c["base_runs"] == 5 and c["head_runs"] == 6, f"{st}: {c}")
        close(c["p_slower"], slower[i], 1e-9, f"{st} p slower")
        close(c["ratio"], float(np.exp(logs["head"][st].mean() - logs["base"][st].mean())), 1e-9, f"{st} ratio")
        expected = "+" if slower_holm[st] < ALPHA and c["ratio"] > SEPARATE_THRESHOLD else "~"
        check(c["mark"] == expected, f"{st}: mark {c['mark']}, expected {expected}")
    check(rows["ca"]["regression"] and not rows["region"]["regression"], "ca is 2.6x slower, region the same")
    print("perf compare runs: ok")


def case_instructions():
    def counts(path, factor):
        base = {"region": 1_000_000, "ca": 2_000_000, "smooth": 500_000}
        with open(path, "w") as f:
            json.dump({"instructions": {"s": {"cpu": {k: round(v * factor.get(k, 1)) for k, v in base.items()}}}}, f)
    counts(f"{WORK}/i-base.json", {})
    counts(f"{WORK}/i-same.json", {"ca": 1.019})             # under 2 %: passes
    counts(f"{WORK}/i-slow.json", {"ca": 1.021, "region": 0.9})  # over 2 %: a regression; region improved
    p = run("perf", "compare", f"{WORK}/i-base.json", f"{WORK}/i-same.json", "--json", f"{WORK}/i.json", expect=0)
    p = run("perf", "compare", f"{WORK}/i-base.json", f"{WORK}/i-slow.json", "--json", f"{WORK}/i.json", expect=6)
    rows = {c["stage"]: c for c in json.load(open(f"{WORK}/i.json"))["comparisons"]}
    check(rows["ca"]["mark"] == "+" and rows["region"]["mark"] == "-" and rows["smooth"]["mark"] == "~",
          f"instruction marks: {[(k, v['mark']) for k, v in rows.items()]}")
    check("s/cpu/ca instructions" in p.stdout, "the regression line must name the stage and metric")
    print("perf compare instructions: ok")


def case_inputs():
    os.makedirs(f"{WORK}", exist_ok=True)
    results_json(f"{WORK}/ok.json", "s", {"region": [1.0] * 20})
    open(f"{WORK}/garbage.json", "w").write("{not json")
    open(f"{WORK}/other.json", "w").write('{"format": "cloudbench-conform/1"}')
    for args, code in [(["compare", f"{WORK}/missing.json", f"{WORK}/ok.json"], 3),
                       (["compare", f"{WORK}/ok.json", f"{WORK}/other.json"], 3),
                       (["compare", f"{WORK}/ok.json"], 2),
                       (["compare", f"{WORK}/ok.json", f"{WORK}/ok.json", "--threshold", "0.5"], 2),
                       (["compare", f"{WORK}/ok.json", f"{WORK}/ok.json", "--frobnicate"], 2),
                       (["frobnicate"], 2),
                       ([], 2),
                       (["history", f"{WORK}/missing.jsonl"], 3),
                       (["export", f"{WORK}/ok.json"], 2)]:
        run("perf", *args, expect=code)
    # A file whose first line is garbage is no history: FILE@-1 is a bad input naming the file and where.
    p = run("perf", "compare", f"{WORK}/garbage.json@-1", f"{WORK}/ok.json", expect=3)
    check("garbage.json: not a " in p.stderr and "line 1, column" in p.stderr,
          f"a corrupt file must be named with file and line: {p.stderr}")
    print("perf inputs: ok")


def record(rid, commit, medians, line_break=False):
    rng = np.random.RandomState(zlib.crc32(rid.encode()))
    results = {"s": {"cpu": {}}}
    for stage, m in medians.items():
        samples = list(np.round(m * np.exp(rng.normal(0, 0.05, 30)), 4))
        results["s"]["cpu"][stage] = {"samples_ms": samples, "median_ms": float(np.median(samples))}
    return {"format": "cloudbench-perf/1", "id": rid, "time": "2026-01-01T00:00:00Z",
            "provenance": {"git": {"commit": commit, "dirty": False}, "build": {"compiler": "GNU 12.2.0"}},
            "results": results, "instructions": {}}


def case_history():
    path = f"{WORK}/history.jsonl"
    if os.path.exists(path):
        os.remove(path)
    # Records appended by perf record's writer are exercised in the record test; here a history is written
    # by hand with a line cut short in the middle, as a crash during a write leaves it.
    lines = [json.dumps(record("r1", "aaa", {"region": 1.0})), json.dumps(record("r2", "aaa", {"region": 1.0}))[:50],
             json.dumps(record("r3", "bbb", {"region": 3.0}))]
    open(path, "w").write("\n".join(lines) + "\n")
    p = run("perf", "compare", f"{path}@r1", f"{path}@-1", expect=6)
    check(f"{path}:2: skipped" in p.stderr, f"the line cut short must be reported with its number: {p.stderr}")
    check("s/cpu/region" in p.stdout, p.stdout)
    run("perf", "compare", f"{path}@r1", f"{path}@r", expect=3)     # ambiguous prefix
    run("perf", "compare", f"{path}@r1", f"{path}@-5", expect=3)    # no such record
    run("perf", "compare", f"{path}@r1", f"{path}@nope", expect=3)  # no such id
    run("perf", "compare", f"{path}@-2", path, expect=6)            # FILE alone: its last record
    # A range pools its records' runs (one each here); its ends in file order, each as a record is named.
    run("perf", "compare", f"{path}@r1:-1", f"{path}@-1", "--json", f"{WORK}/range.json")
    row = json.load(open(f"{WORK}/range.json"))["comparisons"][0]
    check(row["base_runs"] == 2 and row["head_runs"] == 1, f"r1:-1 pools two records' runs: {row}")
    p = run("perf", "compare", f"{path}@-1:r1", f"{path}@-1", expect=3)
    check(f"{path}@-1:r1: the range starts at line 3, after its end at line 1" in p.stderr, p.stderr)
    run("perf", "compare", f"{path}@r1:nope", f"{path}@-1", expect=3)
    # perf history's own options, refused with their range.
    p = run("perf", "history", path, "--alpha", "0", expect=2)
    check("--alpha: needs a number in [1e-12, 1], got '0'" in p.stderr, p.stderr)
    p = run("perf", "history", path, "--clock", "device", expect=2)
    check("--clock: needs wall or cpu, got 'device'" in p.stderr, p.stderr)
    print("perf history records: ok")


def case_changepoints():
    path = f"{WORK}/steps.jsonl"
    rng = np.random.RandomState(3)
    with open(path, "w") as f:
        for i in range(30):
            # "region" rises 1.6x at record 17 (index 17, line 18) with the commit; "ca" only wanders by 8 %.
            commit = "c1" if i < 17 else "c2"
            r = record(f"r{i:02d}", commit, {"region": 1.0 if i < 17 else 1.6, "ca": 2.0 * np.exp(rng.normal(0, 0.08))})
            f.write(json.dumps(r) + "\n")
    p = run("perf", "history", path, "--json", f"{WORK}/steps.json", expect=0)
    doc = json.load(open(f"{WORK}/steps.json"))
    found = [(c["stage"], c["index"]) for c in doc["change_points"]]
    check(found == [("region", 17)], f"change points {found}, expected [('region', 17)]\n{p.stdout}")
    c = doc["change_points"][0]
    check(c["record"] == "r17" and c["line"] == 18, f"the first record after the step: {c}")
    check(any(w.startswith("git.commit: c1 -> c2") for w in c["provenance_changes"]), f"provenance: {c}")
    # A flat noisy history gives none.
    with open(path, "w") as f:
        for i in range(40):
            f.write(json.dumps(record(f"f{i:02d}", "c", {"ca": 2.0 * np.exp(rng.normal(0, 0.1))})) + "\n")
    run("perf", "history", path, "--json", f"{WORK}/flat.json", expect=0)
    check(json.load(open(f"{WORK}/flat.json"))["change_points"] == [], "a flat history must have no change points")
    print("perf history change points: ok")


def case_verdicts():
    """perf history --json's verdict and reason for each series, on both sides of each rule's boundary: fewer than
    2 x --min-segment records; a step under --min-change; a clean step the permutation test cannot reach at
    alpha / m (2 / C(n, nL), worked here with math.comb) and one it can."""
    import math
    path = f"{WORK}/verdicts.jsonl"
    series = {  # stage -> values over 12 records, each record's one run (noise-free, so each split is clean)
        "region": [1.0] * 6 + [1.6] * 6,    # 6 | 6: 2 / C(12, 6) = 0.0022 <= 0.01: a change
        "ca": [1.0] * 7 + [1.6] * 5,        # also 7 | 5 in 12: 2 / C(12, 5) = 0.0025: a change
        "smooth": [1.0] * 6 + [1.05] * 6,   # 5 % < --min-change 10 %
    }
    with open(path, "w") as f:
        for i in range(12):
            results = {"s": {"cpu": {st: {"samples_ms": [v[i]] * 5, "median_ms": v[i]} for st, v in series.items()}}}
            f.write(json.dumps({"format": "cloudbench-perf/1", "id": f"v{i:02d}", "results": results}) + "\n")

    def verdicts(extra, name):
        out = f"{WORK}/{name}.json"
        run("perf", "history", path, "--alpha", "0.03", *extra, "--json", out, expect=0)
        return {v["stage"]: v for v in json.load(open(out))["series"]}

    # alpha 0.03 over 3 series: 0.01 each.
    v = verdicts([], "v12")
    check(v["region"]["verdict"] == "change" and v["region"]["change_points"][0]["index"] == 6, f"region: {v['region']}")
    check(v["ca"]["verdict"] == "change" and v["ca"]["change_points"][0]["index"] == 7, f"ca: {v['ca']}")
    check(v["smooth"]["reason"] == "below_min_change", f"smooth: {v['smooth']}")
    check(abs(v["smooth"]["best_split"]["ratio"] - 1.05) < 1e-9, f"smooth's best split: {v['smooth']}")
    # --min-segment 7: 12 records hold no split with 7 on each side; 14 would.
    v = verdicts(["--min-segment", "7"], "v12s7")
    check(all(x["reason"] == "too_few_records" for x in v.values()), f"12 records, --min-segment 7: {v}")
    # The last 3 records dropped: region is 6 | 3 (2 / C(9, 3) = 0.024 > 0.01), ca 7 | 2 under --min-segment 3.
    lines = open(path).read().splitlines()
    open(path, "w").write("\n".join(lines[:9]) + "\n")
    v = verdicts(["--min-segment", "3"], "v9")
    reachable = 2 / math.comb(9, 3)
    need = next(k for k in range(3, 50) if 2 / math.comb(2 * k, k) <= 0.01)  # 5: 2 / 252
    check(v["region"]["reason"] == "cannot_reach", f"region, 6 | 3: {v['region']}")
    close(v["region"]["best_split"]["reachable_p"], reachable, 1e-9, "the smallest p of a clean 6 | 3 step")
    check(v["region"]["records_needed_each_side"] == need, f"records needed: {v['region']} vs {need}")
    print("perf history verdicts: ok")


def case_gbench():
    compare_py = "/usr/share/benchmark/compare.py"
    if not os.path.exists(compare_py):
        print(f"SKIP: {compare_py} is not installed (Debian's libbenchmark-tools)")
        sys.exit(77)
    rng = np.random.RandomState(5)
    # Five runs a side, each of 30 steps; ca is 2x slower in HEAD, region the same.
    files = {"base": [], "head": []}
    for side, ca in (("base", 2.0), ("head", 4.0)):
        for n in range(5):
            path = f"{WORK}/g-{side}-{n}.json"
            # The CPU time of two threads: about twice the wall time.
            results_json(path, "s", {"region": 1 + 0.01 * rng.rand(30), "ca": ca + 0.01 * rng.rand(30)},
                         cpu={"region": 2 + 0.01 * rng.rand(30), "ca": 2 * ca + 0.01 * rng.rand(30)})
            files[side].append(path)
    for side in ("base", "head"):
        run("perf", "export", "--gbench", f"{WORK}/g-{side}.gbench.json", *files[side], expect=0)
    # Google Benchmark's rows for repetitions: one per run (its mean time per step), then the aggregates.
    doc = json.load(open(f"{WORK}/g-base.gbench.json"))
    ca_rows = [r for r in doc["benchmarks"] if r["run_name"] == "s/cpu/ca"]
    check([r["run_type"] for r in ca_rows] == ["iteration"] * 5 + ["aggregate"] * 3, f"rows: {ca_rows}")
    check([r.get("aggregate_name") for r in ca_rows[5:]] == ["mean", "median", "stddev"], f"aggregates: {ca_rows}")
    check([r["name"] for r in ca_rows[5:]] == ["s/cpu/ca_mean", "s/cpu/ca_median", "s/cpu/ca_stddev"], "names")
    check(all(r["time_unit"] == "us" and r["repetitions"] == 5 for r in ca_rows), f"units: {ca_rows}")
    per_run = [np.mean(json.load(open(f))["backends"]["cpu"]["stages"]["ca"]["samples_ms"]) * 1000
               for f in files["base"]]
    for r, v in zip(ca_rows[:5], per_run):
        close(r["real_time"], v, 1e-12, "a repetition's time: the run's mean step in us")
        check(r["iterations"] == 30, "a run's steps are its iterations")
    close(ca_rows[5]["real_time"], np.mean(per_run), 1e-12, "_mean")
    close(ca_rows[6]["real_time"], np.median(per_run), 1e-12, "_median")
    close(ca_rows[7]["real_time"], np.std(per_run, ddof=1), 1e-9, "_stddev")
    per_run_cpu = [np.mean(json.load(open(f))["backends"]["cpu"]["stages"]["ca"]["cpu"]["samples_ms"]) * 1000
                   for f in files["base"]]
    for r, v in zip(ca_rows[:5], per_run_cpu):
        close(r["cpu_time"], v, 1e-12, "a repetition's CPU time: the run's mean CPU time per step in us")
    close(ca_rows[6]["cpu_time"], np.median(per_run_cpu), 1e-12, "_median CPU time")
    # A record without CPU times (written before records kept them): cpu_time repeats the wall times.
    with open(f"{WORK}/g-h.jsonl", "w") as f:
        f.write(json.dumps(record("r1", "1" * 40, {"ca": 2.0})) + "\n")
    run("perf", "export", "--gbench", f"{WORK}/g-h.gbench.json", f"{WORK}/g-h.jsonl", expect=0)
    check(all(r["cpu_time"] == r["real_time"] for r in json.load(open(f"{WORK}/g-h.gbench.json"))["benchmarks"]),
          "a history's cpu_time repeats its wall time")
    p = subprocess.run(["/usr/bin/python3", compare_py, "-d", f"{WORK}/g-cmp.json", "--no-color", "benchmarks",
                        f"{WORK}/g-base.gbench.json", f"{WORK}/g-head.gbench.json"],
                       capture_output=True, text=True, timeout=120)
    check(p.returncode == 0, f"compare.py failed: {p.stdout}\n{p.stderr}")
    rows = [r for r in json.load(open(f"{WORK}/g-cmp.json")) if r["name"] != "OVERALL_GEOMEAN"]
    by_name = {r["name"]: r for r in rows}
    check({"s/cpu/region", "s/cpu/ca", "s/cpu/ca_median", "s/cpu/region_median"} <= set(by_name),
          f"compare.py saw {sorted(by_name)}")
    # compare.py's change of the median aggregate, and its U test over the five runs a side.
    close(by_name["s/cpu/ca_median"]["measurements"][0]["time"], 1.0, 0.02, "compare.py's change for ca")
    check(by_name["s/cpu/ca"]["utest"]["time_pvalue"] < 0.05, "compare.py's U test must see ca's change")
    check(by_name["s/cpu/ca"]["utest"]["nr_of_repetitions"] == 5, "the U test draws on the five runs")
    check(by_name["s/cpu/region"]["utest"]["time_pvalue"] > 0.05, "region did not change")
    check("s/cpu/ca" in p.stdout and "s/cpu/ca_median" in p.stdout, f"compare.py's table: {p.stdout}")
    print("perf export gbench: ok")


if __name__ == "__main__":
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    {"compare": case_compare, "rounds": case_rounds, "clock": case_clock, "runs": case_runs, "instructions": case_instructions, "inputs": case_inputs, "history": case_history,
     "changepoints": case_changepoints, "verdicts": case_verdicts, "gbench": case_gbench}[CASE]()
