#!/usr/bin/env python3
"""The real-time loop's frame rate (issue 15 item 2): `cloudbench run` on the thesis scenes with a render every step
and F frames per step, on each backend, several times; prints a Markdown table of the loop's fps (results.json
`loop.fps`: frames after warm-up / those steps' wall time) as median [min, max] over the runs.

Usage: measure.py --cli build/release/cloudbench [--scenes thesis-low,thesis-medium] [--frames 1,4,16]
                  [--backends cpu,gl,vk] [--runs 5] [--warmup 100] [--timed 4] [--set PATH=VALUE ...]
Runs are interleaved (run 1 of every configuration, then run 2, ...) so that a slow spell of the machine spreads
over all configurations instead of landing on one.
"""
import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cli", required=True)
    ap.add_argument("--scenes", default="thesis-low,thesis-medium")
    ap.add_argument("--frames", default="1,4,16")
    ap.add_argument("--backends", default="cpu,gl,vk")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--warmup", type=int, default=100)
    ap.add_argument("--timed", type=int, default=4)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--json", help="write every run's loop figures here (after each run)")
    ap.add_argument("--from-json", help="print the table of a --json file and stop")
    a = ap.parse_args()
    configs = [(s, b, int(f)) for s in a.scenes.split(",") for b in a.backends.split(",") for f in a.frames.split(",")]
    figures = {c: [] for c in configs}
    if a.from_json:
        for key, v in json.load(open(a.from_json)).items():
            s, b, fr = key.rsplit("/", 2)
            figures[(s, b, int(fr))] = v
        table(configs, figures)
        return
    with tempfile.TemporaryDirectory() as tmp:
        for run in range(a.runs):
            for scene, backend, frames in configs:
                out = Path(tmp) / f"{Path(scene).stem}-{backend}-{frames}-{run}"
                cmd = [a.cli, "run", scene, "--backend", backend, "--quiet", "--out", str(out),
                       "--set", f"steps={a.warmup + a.timed}", "--set", f"warmup_steps={a.warmup}",
                       "--set", "render.every_steps=1", "--set", f"render.frames_per_step={frames}"]
                for s in a.set:
                    cmd += ["--set", s]
                p = subprocess.run(cmd, capture_output=True, text=True)
                if p.returncode != 0:
                    print(f"{scene} {backend} F={frames} run {run}: exit {p.returncode}: {p.stderr[-400:]}",
                          file=sys.stderr)
                    continue
                b = json.load(open(out / "results.json"))["backends"][backend]
                loop = b["loop"]
                render = b["stages"]["render_splat"]["median_ms"]
                figures[(scene, backend, frames)].append(
                    {"fps": loop["fps"], "step_ms_median": loop["step_ms"]["median_ms"],
                     "step_ms_max": loop["step_ms"]["max_ms"], "render_ms_median": render,
                     "device": b["device"]})
                print(f"{scene} {backend} F={frames} run {run}: {loop['fps']:.2f} fps", file=sys.stderr, flush=True)
                if a.json:
                    json.dump({f"{s}/{b}/{fr}": v for (s, b, fr), v in figures.items()}, open(a.json, "w"), indent=1)
    table(configs, figures)


def table(configs, figures):
    print("| scene | backend | F | loop fps: median [min, max] | runs | step ms (median of medians) | "
          "render ms per step (median) |")
    print("|---|---|---:|---|---:|---:|---:|")
    for c in configs:
        f = figures[c]
        if not f:
            print(f"| {Path(c[0]).stem} | {c[1]} | {c[2]} | (no run) | 0 | | |")
            continue
        fps = [x["fps"] for x in f]
        print(f"| {Path(c[0]).stem} | {c[1]} | {c[2]} | {statistics.median(fps):.2f} [{min(fps):.2f}, {max(fps):.2f}] | "
              f"{len(f)} | {statistics.median(x['step_ms_median'] for x in f):.1f} | "
              f"{statistics.median(x['render_ms_median'] for x in f):.1f} |")


if __name__ == "__main__":
    main()
