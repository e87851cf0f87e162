#!/usr/bin/python3
"""Splat against march on every backend.

Runs scenes/thesis-medium-both (the thesis-medium clouds drawn by both
renderers, 1024x768, cameras "ground" and "above") once per backend per round,
the backends interleaved, and prints each renderer's frame time per camera
(median [min max] over rounds of the per-run median over its render steps) and
the march / splat ratio. On lavapipe and llvmpipe the device is this machine's
CPU.

Usage: tools/splat_vs_march.py [--cli build/release/cloudbench] [--backends cpu,vk,gl]
       [--rounds 3] [--steps 121] [--out /tmp/splat-vs-march]
"""
import argparse
import json
import os
import subprocess
from pathlib import Path
from statistics import median

ROOT = Path(__file__).resolve().parent.parent


def run(cli, backend, out, steps):
    subprocess.run([cli, "run", "thesis-medium-both", "--backend", backend, "--quiet", "--out", str(out),
                    "--steps", str(steps)], check=True, stdout=subprocess.DEVNULL)
    b = json.loads((out / "results.json").read_text())["backends"][backend]
    return {"device": b["device"],
            "splat": {cam: f["median_ms"] for cam, f in b["frames"].items()},
            "march": {cam: f["median_ms"] for cam, f in b["march_frames"].items()}}


def fmt(values):
    return f"{median(values):.0f} [{min(values):.0f} {max(values):.0f}]"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/release/cloudbench"))
    ap.add_argument("--backends", default="cpu,vk,gl")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--steps", type=int, default=121, help="renders at steps 100, 110, ... (the scene's warm-up is 100)")
    ap.add_argument("--out", default="/tmp/splat-vs-march")
    a = ap.parse_args()
    backends = a.backends.split(",")
    runs = {b: [] for b in backends}
    loads = []
    for _ in range(a.rounds):
        for b in backends:
            loads.append(os.getloadavg()[0])
            runs[b].append(run(a.cli, b, Path(a.out) / b, a.steps))
    print(f"thesis-medium-both, 1024x768, {a.rounds} interleaved rounds, render steps 100..{a.steps - 1} every 10; "
          f"1-minute load {min(loads):.1f}..{max(loads):.1f}. Frame ms, median [min max] over rounds.\n")
    print("| backend (device) | camera | render_splat ms | render_march ms | march / splat |")
    print("|---|---|---|---|---|")
    for b in backends:
        for cam in runs[b][0]["splat"]:
            s = [r["splat"][cam] for r in runs[b]]
            m = [r["march"][cam] for r in runs[b]]
            print(f"| {b} ({runs[b][0]['device']}) | {cam} | {fmt(s)} | {fmt(m)} | {median(m) / median(s):.1f} |")


if __name__ == "__main__":
    main()
