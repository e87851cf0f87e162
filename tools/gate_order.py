#!/usr/bin/python3
"""How the interleaved gate's order of runs within a round bears on its false
alarms, measured on one long interleave of a binary against itself.

  gate_order.py KEPT_DIR [--rounds K] [--alpha A] [--threshold R] [--draws N]

KEPT_DIR is what `cloudbench perf compare --interleave B B SCENE --backend cpu
--clock cpu --rounds 1000 --keep KEPT_DIR` left. Both sides being one binary,
the labels carry nothing: the runs are one series of slots in the order they
ran, and any order of a round's two runs can be laid over it afterwards. For
each order (ABBA, and N draws of a fair coin a round) the tool forms the
log-ratios the gate would have seen, cuts them into windows of K rounds (ABBA:
every window starting on an even round; a coin: disjoint windows) and reports,
per stage,

  - var(sum) / sum(d^2): how much the K log-ratios' sum varies against what the
    sign-flip test assumes (1 when the rounds are exchangeable; above 1 the test
    alarms more often than alpha, below 1 less often);
  - the share of windows with the one-sided exact sign-flip p below 0.05, 0.01
    and alpha / stages (what Holm needs of the smallest p);

and per order the windows with a false alarm: any stage with Holm p < alpha and
ratio > R. Last, each stage's correlation between runs 1 to 4 apart, which is
what an order that is not drawn at random must cancel.
"""
import argparse
import json
import math
import os

import numpy as np


def slot_series(folder):
    """Each stage's log per-run median CPU time, in the order the runs ran."""
    manifest = json.load(open(os.path.join(folder, "interleave.json")))
    runs = []
    for run in manifest["runs"]:
        results = json.load(open(os.path.join(folder, run["folder"], "results.json")))
        runs.append({stage: math.log(v["cpu"]["median_ms"]) for stage, v in results["backends"]["cpu"]["stages"].items()})
    runs = runs[: len(runs) // 2 * 2]
    loads = [run["load"][0] for run in manifest["runs"] if run.get("load")]
    return {stage: np.array([r[stage] for r in runs]) for stage in runs[0]}, loads


def sign_flip_p(d):
    """One-sided exact sign-flip p over all 2^K patterns, two halves met in the middle."""
    def sums(values):
        s = np.zeros(1)
        for x in values:
            s = np.concatenate([s + x, s - x])
        return np.sort(s)
    half = len(d) // 2
    a, b = sums(d[:half]), sums(d[half:])
    observed = d.sum()
    at_least = observed - abs(observed) * 1e-14
    return np.sum(len(b) - np.searchsorted(b, at_least - a, side="left")) / 2.0 ** len(d)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("kept")
    parser.add_argument("--rounds", type=int, default=17)
    parser.add_argument("--alpha", type=float, default=0.01)
    parser.add_argument("--threshold", type=float, default=1.1)
    parser.add_argument("--draws", type=int, default=20)
    args = parser.parse_args()
    series, loads = slot_series(args.kept)
    stages = sorted(series)
    rounds = len(series[stages[0]]) // 2
    print(f"{2 * rounds} runs, {rounds} rounds; 1-minute load average at a run's start: median "
          f"{np.median(loads):.1f}, range {min(loads):.1f} to {max(loads):.1f}")
    rng = np.random.default_rng(3)
    orders = [("ABBA", [np.arange(rounds) % 2], range(0, rounds - args.rounds + 1, 2)),
              ("coin", [rng.integers(0, 2, rounds) for _ in range(args.draws)],
               range(0, rounds - args.rounds + 1, args.rounds))]
    holm_level = args.alpha / len(stages)
    for name, draws, starts in orders:
        windows = alarms = 0
        rows = {stage: [] for stage in stages}
        for head_first in draws:
            # head_first[i] = 1: HEAD ran in the round's first slot.
            logs = {s: np.where(head_first == 1, x[0::2] - x[1::2], x[1::2] - x[0::2]) for s, x in series.items()}
            for start in starts:
                alarm = False
                for stage in stages:
                    d = logs[stage][start:start + args.rounds]
                    p = sign_flip_p(d)
                    rows[stage].append((d.sum() ** 2, (d ** 2).sum(), p))
                    alarm |= p * len(stages) < args.alpha and math.exp(d.mean()) > args.threshold
                windows += 1
                alarms += alarm
        print(f"{name}: {windows} windows of {args.rounds} rounds, false alarms (Holm p < {args.alpha} and ratio > "
              f"{args.threshold} on any of {len(stages)} stages): {alarms} ({100 * alarms / windows:.2f} %)")
        print(f"  {'stage':13s} var(sum)/sum(d^2)  p<0.05  p<0.01  p<{holm_level:.2g}")
        for stage in stages:
            v = np.array(rows[stage])
            print(f"  {stage:13s} {v[:, 0].mean() / v[:, 1].mean():17.2f}  {np.mean(v[:, 2] < 0.05):6.3f}  "
                  f"{np.mean(v[:, 2] < 0.01):6.3f}  {np.mean(v[:, 2] < holm_level):7.4f}")
    print("correlation between runs 1, 2, 3 and 4 apart:")
    for stage in stages:
        y = series[stage] - series[stage].mean()
        print(f"  {stage:13s} " + " ".join(f"{np.corrcoef(y[:-k], y[k:])[0, 1]:+.2f}" for k in (1, 2, 3, 4)))


if __name__ == "__main__":
    main()
