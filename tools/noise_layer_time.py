#!/usr/bin/python3
"""The CPU ray march's time per frame on scenes/noise-layer.json (the 100 ms target) at 1280x720, for one or more
builds (or SIMD targets) interleaved round by round, so that a loaded machine weighs on each alike.

Each round runs, for every build, the scene for --frames frames (static clouds, the march rendering every step) and
reads the march's CPU time (the process's, all threads, over the stage's calls) and wall time of each frame from
results.json. Prints, per build, medians [min max] over every frame of every round, the samples, the lanes'
utilisation (lane_steps / lane_slots where the build counts them) and the paired ratio of each round's median CPU
time to the first build's in that round. Run from the repository root:

  tools/noise_layer_time.py                                        this build, the best SIMD target
  tools/noise_layer_time.py --cli OLD/cloudbench --cli build/release/cloudbench --rounds 8
  tools/noise_layer_time.py --cpu-isa avx512 --cpu-isa avx2 --set march.light='"march"'
"""
import argparse
import json
import os
import subprocess
import tempfile
from statistics import median


def run(cli, isa, sets, frames, out):
    cmd = [cli, "run", "noise-layer", "--backend", "cpu", "--quiet", "--out", out, "--set", "warmup_steps=0",
           "--set", "render.every_steps=1", "--set", "steps=%d" % frames]
    if isa:
        cmd += ["--cpu-isa", isa]
    for s in sets:
        cmd += ["--set", s]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    cpu = json.load(open(os.path.join(out, "results.json")))["backends"]["cpu"]
    return cpu["stages"]["render_march"]["cpu"]["samples_ms"], cpu["march_frames"]["above"]


def spread(values, fmt="%.1f"):
    return (fmt + " [" + fmt + " " + fmt + "]") % (median(values), min(values), max(values))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", action="append", help="a cloudbench binary (repeat to compare; default the build's)")
    ap.add_argument("--cpu-isa", action="append", help="a SIMD target (repeat to compare; default the best)")
    ap.add_argument("--set", action="append", default=[], help="a scene override for every run")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--frames", type=int, default=3, help="frames per run")
    args = ap.parse_args()
    builds = [(cli, isa) for cli in (args.cli or ["build/release/cloudbench"]) for isa in (args.cpu_isa or [None])]
    cpu = {b: [] for b in builds}
    wall = {b: [] for b in builds}
    ratio = {b: [] for b in builds}
    last = {}
    loads = []
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.rounds):
            loads.append(os.getloadavg()[0])
            for n, b in enumerate(builds):
                c, f = run(b[0], b[1], args.set, args.frames, os.path.join(tmp, "b%d" % n))
                cpu[b].extend(c)
                wall[b].extend(f["samples_ms"])
                last[b] = f
                ratio[b].append(median(c) / median(cpu[builds[0]][-len(c):]))
    print("load average at each round:", " ".join("%.1f" % x for x in loads))
    for b in builds:
        f = last[b]
        lanes = ""
        if f.get("lane_slots") and f["lane_slots"][-1]:
            lanes = ", lanes %.1f %% full" % (100.0 * f["lane_steps"][-1] / f["lane_slots"][-1])
        print("%s%s: march CPU ms/frame %s, wall ms/frame %s (%d frames); samples %d, light %d, bricks skipped %d%s;"
              " CPU time against the first x%s" % (b[0], " --cpu-isa " + b[1] if b[1] else "", spread(cpu[b]),
                                                   spread(wall[b]), len(wall[b]), f["samples"][-1],
                                                   f["light_samples"][-1], f["bricks_skipped"][-1], lanes,
                                                   spread(ratio[b], "%.3f")))


if __name__ == "__main__":
    main()
