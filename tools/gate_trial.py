#!/usr/bin/python3
"""The regression gate's trial: how often `perf compare --interleave` raises a
false alarm on identical builds and how often it catches a slowdown planted in
one stage, beside Google Benchmark's compare.py on the same runs
(docs/performance.md, "The regression gate"; results in reports/perf/).

  gate_trial.py collect CLOUDBENCH WORKDIR [options]
      runs the planned pairs, each one `cloudbench perf compare --interleave
      --keep WORKDIR/pairs/ID`: identical pairs (CLOUDBENCH against itself) and
      planted pairs (HEAD is CLOUDBENCH with CLOUDBENCH_TEST_SLOWDOWN=STAGE:F).
      The pairs of every kind and scene alternate, so that a change in the
      machine's load falls on all of them. A pair already kept is not run again.
  gate_trial.py judge CLOUDBENCH WORKDIR [--clock cpu|wall] [--first-rounds K] [--markdown FILE] [--csv FILE]
                     [-- COMPARE OPTIONS]
      judges every kept pair again, on the CPU clock (the default, as the gate
      runs in CI) or on wall time, with CLOUDBENCH's `perf compare WORKDIR/pairs/ID`
      (and the compare options given after --) and with compare.py on the
      same runs (`perf export --gbench` of each side; a stage is flagged when
      compare.py's U test gives p < 0.05 and its median is more than 5 % slower)
      and with the gate cloudbench had before runs were the sample (every
      step pooled, one-sided Mann-Whitney, Holm, ratio over --pooled-threshold,
      1.1), and prints the table: false alarms, planted slowdowns caught, wrong-stage
      flags, the planted stage's and its neighbours' measured ratios, the load
      average over the runs and what a pair cost. --first-rounds K judges only
      each pair's first K rounds (a trimmed copy, WORKDIR/pairs/ID/first-K).

collect options: --rounds K (default: perf compare's own), --null N (40), --planted N (8 a scene and
factor), --stage S (smooth), --factors F,F (1.25,1.5), --null-scenes
(ci-small,thesis-low,thesis-medium), --planted-scenes (thesis-low,thesis-medium),
--steps N and --set PATH=VALUE (passed to every run), --clock (the verdict
logged as each pair ends; the runs are the same on either clock).
"""
import argparse
import glob
import json
import math
import os
import shutil
import stat
import statistics
import subprocess
import sys
import time

COMPARE_PY = "/usr/share/benchmark/compare.py"
# The stages the simulation runs each step, in order: a planted stage's neighbours are the ones beside it.
STAGE_ORDER = ["region", "ca", "smooth", "density", "shade", "shadow", "render_splat"]


def plan(args):
    """Every pair: (id, scene, factor or None), the kinds interleaved."""
    nulls = [(s, None) for s in args.null_scenes]
    planted = [(s, f) for f in args.factors for s in args.planted_scenes]
    null_list = [nulls[i % len(nulls)] for i in range(args.null)]
    planted_list = [p for n in range(args.planted) for p in planted]
    pairs, counters = [], {}
    # Alternate: one planted pair after every (null / planted) identical ones, as evenly as the counts allow.
    total = len(null_list) + len(planted_list)
    ni = pi = 0
    for k in range(total):
        take_null = pi >= len(planted_list) or (ni < len(null_list) and ni * len(planted_list) <= pi * len(null_list))
        scene, factor = null_list[ni] if take_null else planted_list[pi]
        ni, pi = (ni + 1, pi) if take_null else (ni, pi + 1)
        kind = "null" if factor is None else f"x{factor:g}"
        counters[(scene, kind)] = counters.get((scene, kind), 0) + 1
        pairs.append((f"{scene}-{kind}-{counters[(scene, kind)]:02d}", scene, factor))
    return pairs


def wrapper(work, stage, factor):
    path = os.path.join(work, f"slow-{stage}-{factor:g}")
    with open(path, "w") as f:
        f.write(f'#!/bin/sh\nCLOUDBENCH_TEST_SLOWDOWN={stage}:{factor:g} exec "$CLOUDBENCH_TRIAL_BINARY" "$@"\n')
    os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
    return path


def collect(args):
    cli = os.path.abspath(args.cloudbench)
    os.makedirs(os.path.join(args.work, "pairs"), exist_ok=True)
    extra = (["--steps", str(args.steps)] if args.steps else []) + [x for s in args.set for x in ("--set", s)]
    env = dict(os.environ, CLOUDBENCH_TRIAL_BINARY=cli)
    trial = {"cloudbench": cli, "rounds": args.rounds, "stage": args.stage, "run_options": extra}
    with open(os.path.join(args.work, "trial.json"), "w") as f:
        json.dump(trial, f, indent=1)
    for pair_id, scene, factor in plan(args):
        keep = os.path.join(args.work, "pairs", pair_id)
        if os.path.exists(os.path.join(keep, "pair.json")):
            continue
        head = cli if factor is None else wrapper(args.work, args.stage, factor)
        start = time.time()
        rounds = ["--rounds", str(args.rounds)] if args.rounds else []
        p = subprocess.run([cli, "perf", "compare", "--interleave", cli, head, scene, "--backend", "cpu", *rounds,
                            "--clock", args.clock, "--keep", keep, "--quiet", *extra],
                           capture_output=True, text=True, env=env)
        seconds = time.time() - start
        if p.returncode not in (0, 6):
            print(f"{pair_id}: perf compare exited {p.returncode}\n{p.stderr}", file=sys.stderr)
        with open(os.path.join(keep, "pair.json"), "w") as f:
            json.dump({"scene": scene, "factor": factor, "stage": args.stage if factor else None,
                       "seconds": round(seconds, 1), "exit": p.returncode}, f)
        print(f"{time.strftime('%H:%M:%S')} {pair_id}: exit {p.returncode}, {seconds:.0f} s, load "
              f"{open('/proc/loadavg').read().split()[0]}", flush=True)


def first_rounds(keep, rounds):
    """A copy of the kept pair KEEP holding only its first ROUNDS rounds (KEEP/first-ROUNDS), to judge what fewer
    rounds would have said on the same runs."""
    manifest = json.load(open(os.path.join(keep, "interleave.json")))
    if rounds >= manifest["rounds"]:
        return keep
    trimmed = os.path.join(keep, f"first-{rounds}")
    if not os.path.exists(os.path.join(trimmed, "interleave.json")):
        manifest["rounds"] = rounds
        manifest["runs"] = [r for r in manifest["runs"] if r["round"] < rounds]
        for r in manifest["runs"]:
            os.makedirs(os.path.join(trimmed, r["folder"]), exist_ok=True)
            results = os.path.join(keep, r["folder"], "results.json")
            if os.path.exists(results):
                shutil.copyfile(results, os.path.join(trimmed, r["folder"], "results.json"))
        with open(os.path.join(trimmed, "interleave.json"), "w") as f:
            json.dump(manifest, f, indent=1)
    return trimmed


def gate_flags(cli, keep, clock, options):
    out = os.path.join(keep, "judged.json")
    p = subprocess.run([cli, "perf", "compare", keep, "--clock", clock, "--json", out, *options],
                       capture_output=True, text=True)
    if p.returncode not in (0, 6):
        sys.exit(f"{keep}: perf compare exited {p.returncode}\n{p.stdout}\n{p.stderr}")
    doc = json.load(open(out))
    rows = [c for c in doc["comparisons"] if c["metric"] == "time"]
    return {c["stage"] for c in rows if c["regression"]}, {c["stage"]: c["ratio"] for c in rows}, \
        {c["stage"] for c in rows if c["mark"] == "?"}


def compare_py_flags(cli, keep, clock):
    """compare.py's verdict on the same runs: U test p < 0.05 and the median more than 5 % slower, on its "Time"
    columns (wall time) or its "CPU" ones (perf export's cpu_time)."""
    column = "cpu" if clock == "cpu" else "time"
    manifest = json.load(open(os.path.join(keep, "interleave.json")))
    files = {}
    for side in ("base", "head"):
        folders = [os.path.join(keep, r["folder"]) for r in manifest["runs"] if r["side"] == side]
        files[side] = os.path.join(keep, f"gbench-{side}.json")
        subprocess.run([cli, "perf", "export", "--gbench", files[side], *folders], check=True, capture_output=True)
    dump = os.path.join(keep, "compare-py.json")
    subprocess.run(["/usr/bin/python3", COMPARE_PY, "-d", dump, "--no-color", "benchmarks", files["base"],
                    files["head"]], check=True, capture_output=True)
    flagged = set()
    for row in json.load(open(dump)):
        if row.get("run_type") != "aggregate" or row.get("aggregate_name") != "median":
            continue
        name = row["name"].rsplit("_median", 1)[0]
        utest = next((r["utest"] for r in json.load(open(dump)) if r["name"] == name and r["utest"]), {})
        if utest and utest[f"{column}_pvalue"] < 0.05 and row["measurements"][0][column] > 0.05:
            flagged.add(name.split("/")[-1])
    return flagged


def pooled_steps_flags(keep, clock, threshold, alpha=0.01):
    """What a gate on the steps pooled over each side's runs would flag (the gate before runs were the sample):
    one-sided Mann-Whitney U (SciPy, asymptotic), Holm over the stages, the ratio of medians over `threshold`."""
    import numpy as np
    from scipy import stats
    manifest = json.load(open(os.path.join(keep, "interleave.json")))
    pooled = {"base": {}, "head": {}}
    for r in manifest["runs"]:
        path = os.path.join(keep, r["folder"], "results.json")
        if not os.path.exists(path):
            continue
        for stage, v in json.load(open(path))["backends"]["cpu"].get("stages", {}).items():
            samples = v["cpu"]["samples_ms"] if clock == "cpu" else v["samples_ms"]
            pooled[r["side"]].setdefault(stage, []).extend(samples)
    names = sorted(set(pooled["base"]) & set(pooled["head"]))
    p = [stats.mannwhitneyu(pooled["head"][s], pooled["base"][s], alternative="greater", method="asymptotic").pvalue
         for s in names]
    order, adjusted, running = sorted(range(len(p)), key=lambda i: p[i]), [0.0] * len(p), 0.0
    for rank, i in enumerate(order):
        running = max(running, min(1.0, (len(p) - rank) * p[i]))
        adjusted[i] = running
    return {s for s, a in zip(names, adjusted)
            if a < alpha and np.median(pooled["head"][s]) / np.median(pooled["base"][s]) > threshold}


def spread(values):
    if not values:
        return "-"
    return f"{statistics.median(values):.2f} ({min(values):.2f}-{max(values):.2f})"


def judge(args):
    cli = os.path.abspath(args.cloudbench)
    trial = json.load(open(os.path.join(args.work, "trial.json")))
    pairs = sorted(glob.glob(os.path.join(args.work, "pairs", "*", "pair.json")))
    methods = ("perf compare", "compare.py", "pooled steps")
    tally = {m: {} for m in methods}  # method -> (scene, kind) -> [pairs, caught or alarmed, wrong-stage flags]
    ratios, neighbours, loads, seconds, unjudged = {}, {}, [], {}, {}
    for path in pairs:
        keep = os.path.dirname(path)
        if args.first_rounds:
            keep = first_rounds(keep, args.first_rounds)
        pair = json.load(open(path))
        scene, factor = pair["scene"], pair["factor"]
        stage = pair["stage"] or trial["stage"]
        kind = "identical" if factor is None else f"x{factor:g}"
        manifest = json.load(open(os.path.join(keep, "interleave.json")))
        loads += [r["load"][0] for r in manifest["runs"] if r.get("load")]
        # A trimmed pair costs its share of the whole pair's time.
        seconds.setdefault(scene, []).append(
            pair["seconds"] * manifest["rounds"] / json.load(open(os.path.join(os.path.dirname(path),
                                                                               "interleave.json")))["rounds"])
        flags, measured, cannot = gate_flags(cli, keep, args.clock, args.options)
        for s in cannot:
            unjudged[s] = unjudged.get(s, 0) + 1
        verdicts = {"perf compare": flags}
        if os.path.exists(COMPARE_PY):
            verdicts["compare.py"] = compare_py_flags(cli, keep, args.clock)
        verdicts["pooled steps"] = pooled_steps_flags(keep, args.clock, args.pooled_threshold)
        for method, flagged in verdicts.items():
            t = tally[method].setdefault((scene, kind), [0, 0, 0])
            t[0] += 1
            if factor is None:
                t[1] += bool(flagged)
            else:
                t[1] += stage in flagged
                t[2] += bool(flagged - {stage})
        if factor is not None:
            ratios.setdefault((scene, kind), []).append(measured.get(stage, math.nan))
            i = STAGE_ORDER.index(stage)
            for n in STAGE_ORDER[max(0, i - 1):i] + STAGE_ORDER[i + 1:i + 2]:
                neighbours.setdefault((scene, kind, n), []).append(measured.get(n, math.nan))
        else:
            for s, r in measured.items():
                neighbours.setdefault((scene, "identical", s), []).append(r)
    rounds = sorted({min(json.load(open(os.path.join(os.path.dirname(p), "interleave.json")))["rounds"],
                         args.first_rounds or math.inf) for p in pairs})
    lines = [f"Trial of {len(pairs)} pairs, {'/'.join(map(str, rounds))} rounds each (ABBA), cpu backend, run options "
             f"{' '.join(trial['run_options']) or '(none)'}; planted stage `{trial['stage']}`; judged with "
             f"`perf compare --clock {args.clock} {' '.join(args.options)}`"
             f"{' (compare.py on its CPU columns, pooled steps of CPU time)' if args.clock == 'cpu' else ''}.", "",
             f"Load average (1 min) at the start of each run: median {statistics.median(loads):.2f}, "
             f"{min(loads):.2f} to {max(loads):.2f}." if loads else "", "",
             "| method | scene | pairs | false alarms / caught | wrong-stage flags |", "|---|---|---|---|---|"]
    for method in methods:
        for (scene, kind), (n, hits, wrong) in sorted(tally[method].items()):
            what = f"{hits} false alarms" if kind == "identical" else f"{kind}: {hits} of {n} caught"
            lines.append(f"| {method} | {scene} | {n} | {what} | {'-' if kind == 'identical' else wrong} |")
    lines += ["", "Measured ratios (perf compare's estimate), median (range):", "",
              "| scene | pairs | planted stage | neighbours |", "|---|---|---|---|"]
    for (scene, kind), rs in sorted(ratios.items()):
        near = "; ".join(f"{n} {spread(v)}" for (s, k, n), v in sorted(neighbours.items()) if s == scene and k == kind)
        lines.append(f"| {scene} | {kind} | {spread(rs)} | {near} |")
    for scene in sorted({s for (s, k, n) in neighbours if k == "identical"}):
        every = [r for (s, k, n), v in neighbours.items() if s == scene and k == "identical" for r in v]
        lines.append(f"| {scene} | identical | every stage {spread(every)} | |")
    lines += ["", "What a pair cost (both sides' runs, wall time): " +
              "; ".join(f"{s} {spread(v)} s" for s, v in sorted(seconds.items())) + "."]
    if unjudged:
        lines.append("Stages perf compare could not judge (pairs): " +
                     ", ".join(f"{s} {n}" for s, n in sorted(unjudged.items())) + ".")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.csv:
        write_runs_csv(args.csv, pairs)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(text)


def write_runs_csv(path, pairs):
    """Each run's statistics per stage, for re-checking a verdict without the kept folders."""
    import numpy as np
    with open(path, "w") as f:
        f.write("pair,scene,planted,side,round,load1,stage,steps,median_ms,q25_ms,q10_ms,min_ms,"
                "cpu_median_ms,cpu_q25_ms,cpu_min_ms\n")
        for pair_path in pairs:
            keep = os.path.dirname(pair_path)
            pair = json.load(open(pair_path))
            planted = f"{pair['stage']}:{pair['factor']:g}" if pair["factor"] else ""
            for r in json.load(open(os.path.join(keep, "interleave.json")))["runs"]:
                results = os.path.join(keep, r["folder"], "results.json")
                if not os.path.exists(results):
                    continue
                for stage, v in sorted(json.load(open(results))["backends"]["cpu"].get("stages", {}).items()):
                    a = np.array(v["samples_ms"])
                    c = np.array(v["cpu"]["samples_ms"]) if "cpu" in v else None
                    cpu = f"{np.median(c):.6g},{np.quantile(c, 0.25):.6g},{c.min():.6g}" if c is not None else ",,"
                    f.write(f"{os.path.basename(keep)},{pair['scene']},{planted},{r['side']},{r['round']},"
                            f"{r['load'][0] if r.get('load') else ''},{stage},{len(a)},{np.median(a):.6g},"
                            f"{np.quantile(a, 0.25):.6g},{np.quantile(a, 0.1):.6g},{a.min():.6g},{cpu}\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("action", choices=["collect", "judge"])
    parser.add_argument("cloudbench")
    parser.add_argument("work")
    parser.add_argument("--rounds", type=int)
    parser.add_argument("--null", type=int, default=40)
    parser.add_argument("--planted", type=int, default=8)
    parser.add_argument("--stage", default="smooth")
    parser.add_argument("--factors", type=lambda s: [float(x) for x in s.split(",")], default=[1.25, 1.5])
    parser.add_argument("--null-scenes", type=lambda s: s.split(","), default=["ci-small", "thesis-low",
                                                                              "thesis-medium"])
    parser.add_argument("--planted-scenes", type=lambda s: s.split(","), default=["thesis-low", "thesis-medium"])
    parser.add_argument("--steps", type=int)
    parser.add_argument("--set", action="append", default=[])
    parser.add_argument("--first-rounds", type=int, help="judge: only each pair's first K rounds")
    parser.add_argument("--clock", choices=["cpu", "wall"], default="cpu",
                        help="the time every method judges: the process's CPU time (the gate in CI) or wall time")
    parser.add_argument("--markdown")
    parser.add_argument("--csv", help="judge: also write each run's statistics per stage to this file")
    parser.add_argument("--pooled-threshold", type=float, default=1.1,
                        help="judge: the ratio the pooled-steps gate needs (the gate before runs were the sample)")
    # Everything after "--" goes to perf compare as it is.
    argv = sys.argv[1:]
    cut = argv.index("--") if "--" in argv else len(argv)
    args = parser.parse_args(argv[:cut])
    args.options = argv[cut + 1:]
    collect(args) if args.action == "collect" else judge(args)


if __name__ == "__main__":
    main()
