#!/usr/bin/python3
"""Fizimayer's thesis, section 8.1.2 ("computation over multiple frames") on every backend.

Runs thesis-medium (256x256x32, the automaton, shade and shadow, render_splat with its two cameras) with
render.slices_per_frame = 0 (the whole step in one frame), 1, 4 and 32, rendering every step after the warm-up,
interleaved (round, then setting, then backend innermost), and prints per backend a Markdown table:

- frames a step takes: the loop's frames per step (results.json loop.frames / loop.steps), checked against the count
  worked out from the grid: ca, region and smooth ceil(32 / s) each, density ceil(8 / s) (rows of tiles), shade
  ceil(n_w / s) (the sweep's slices: 256 with the scene's low sun), shadow 1; and the same without shade and shadow,
  which is what the thesis counts (32 + 32 + 32 + 32 = 128 frames at one slice per frame);
- the update period at 60 fps: frames a step takes / 60;
- each frame's wall time (results.json loop.frame_ms: its share of the next step and its renders) as median
  [q1 q3], and the slowest frame;
- the added cost per frame: the median frame minus the median frame that renders only (from the unsliced run at
  8 frames per step, whose frames 1..7 do nothing else); unsliced, the first frame's added cost is the whole step.

Usage: tools/time_slicing_table.py [--cli build/release/cloudbench] [--backends cpu,gl,vk] [--rounds 2]
       [--size 320x240] [--warmup 100] [--steps 2] [--out /tmp/time-slicing] [--json reports/loop/time-slicing.json]
The render size defaults to 320x240 so that the renders do not drown the simulation's share of a frame (the
thesis's 1024x768 frames are Tables 8.2-8.4, tools/thesis_tables.py); --size 1024x768 gives the thesis's.
"""
import argparse
import json
import math
import subprocess
import sys
from pathlib import Path
from statistics import median

ROOT = Path(__file__).resolve().parent.parent
SLICES = [0, 1, 4, 32]
RENDER_ONLY_FRAMES = 8  # frames per step of the unsliced run: frame 0 carries the step, 1..7 render only
# Fizimayer's thesis, section 8.1.2: one slice of 32 per frame; 128 frames (32 region + 32 simulation +
# 32 smoothing + 32 density) per step, an update every 2.13 s at 60 fps; the simulation "did not affect framerate".
THESIS = {"frames": 128, "period_s": 2.13, "gpu": "NVIDIA GeForce 8700M GT"}


def quantile(values, q):
    s = sorted(values)
    if not s:
        return float("nan")
    x = (len(s) - 1) * q
    lo = math.floor(x)
    hi = min(lo + 1, len(s) - 1)
    return s[lo] + (s[hi] - s[lo]) * (x - lo)


def run_once(cli, backend, slices, out, warmup, steps, size):
    w, h = size.split("x")
    args = [cli, "run", "thesis-medium", "--backend", backend, "--quiet", "--out", str(out),
            "--set", f"steps={warmup + steps + 1}", "--set", f"warmup_steps={warmup}", "--set", "render.every_steps=1",
            "--set", f"render.width={w}", "--set", f"render.height={h}",
            "--set", f"render.slices_per_frame={slices}"]
    if slices == 0:
        args += ["--set", f"render.frames_per_step={RENDER_ONLY_FRAMES}"]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    r = json.loads((out / "results.json").read_text())
    b = r["backends"][backend]
    loop = b["loop"]
    frames = loop["frame_ms"]
    # The last step computes nothing ahead (there is no next step): it draws render.frames_per_step frames, left out.
    last = RENDER_ONLY_FRAMES if slices == 0 else 1
    samples = frames["samples_ms"][:-last]
    run = {"device": b["device"], "frames_per_step": (loop["frames"] - last) / (loop["steps"] - 1),
           "samples_ms": samples, "slowest": frames["slowest"], "max_ms": frames["max_ms"]}
    if slices == 0:
        run["step_frames_ms"] = samples[0::RENDER_ONLY_FRAMES]
        run["render_only_ms"] = [x for i, x in enumerate(samples) if i % RENDER_ONLY_FRAMES]
    return run


def expected_frames(slices, nz=32, tile_rows=8, sweep=256):
    """Frames a step takes at `slices` per frame: with and without shade and shadow (the thesis's count)."""
    per = lambda n: math.ceil(n / slices)  # noqa: E731
    simulation = 3 * per(nz) + per(tile_rows)
    return simulation + per(sweep) + 1, simulation


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/release/cloudbench"))
    ap.add_argument("--backends", default="cpu,gl,vk")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--warmup", type=int, default=100, help="steps before the first render (the scene's own)")
    ap.add_argument("--steps", type=int, default=2,
                    help="timed steps after the warm-up (one more runs last, which computes nothing ahead)")
    ap.add_argument("--out", default="/tmp/time-slicing")
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    backends = a.backends.split(",")
    runs = {b: {s: [] for s in SLICES} for b in backends}
    for rnd in range(a.rounds):
        for s in SLICES:
            for b in backends:
                out = Path(a.out) / f"{b}-{s}-{rnd}"
                try:
                    runs[b][s].append(run_once(a.cli, b, s, out, a.warmup, a.steps, a.size))
                except subprocess.CalledProcessError as e:
                    print(f"{b} slices {s}: failed ({e.returncode}); skipped", file=sys.stderr)
                print(f"round {rnd} slices {s} {b} done", file=sys.stderr)
    bad = False
    print(f"# Fizimayer's thesis, section 8.1.2 on every backend: thesis-medium, {a.size}, {a.steps} timed steps x "
          f"{a.rounds} rounds\n")
    for b in backends:
        if not runs[b][0]:
            continue
        print(f"## {b}: {runs[b][0][0]['device']}\n")
        render_only = [x for r in runs[b][0] for x in r["render_only_ms"]]
        base = median(render_only)
        print(f"Render-only frame (unsliced run, frames 1..7 of each step): median {base:.2f} ms "
              f"[q1 {quantile(render_only, .25):.2f}, q3 {quantile(render_only, .75):.2f}].\n")
        print("| slices per frame | frames a step takes (without shade, shadow) | update period at 60 fps | "
              "frame ms median [q1 q3] | slowest frame ms (what it computed) | added per frame, ms |")
        print("|---|---|---|---|---|---|")
        for s in SLICES:
            rs = runs[b][s]
            if not rs:
                continue
            if s == 0:
                step_frames = [x for r in rs for x in r["step_frames_ms"]]
                m = median(step_frames)
                print(f"| whole step in one frame | 1 | {1 / 60:.3f} s | {m:.2f} [{quantile(step_frames, .25):.2f} "
                      f"{quantile(step_frames, .75):.2f}] (the step's frame) | {max(r['max_ms'] for r in rs):.2f} | "
                      f"{m - base:.2f} (once per step) |")
                continue
            per_step = rs[0]["frames_per_step"]
            total, simulation = expected_frames(s)
            if abs(per_step - total) > 1e-9:
                print(f"{b} slices {s}: {per_step} frames per step, expected {total}", file=sys.stderr)
                bad = True
            samples = [x for r in rs for x in r["samples_ms"]]
            slow = max(rs, key=lambda r: r["max_ms"])
            m = median(samples)
            print(f"| {s} | {per_step:.0f} ({simulation}) | {per_step / 60:.2f} s ({simulation / 60:.2f} s) | "
                  f"{m:.2f} [{quantile(samples, .25):.2f} {quantile(samples, .75):.2f}] | {slow['max_ms']:.2f} "
                  f"({slow['slowest']['work'] or 'renders only'}) | {m - base:.2f} |")
        print(f"| thesis, 1 of 32 slices, {THESIS['gpu']} | ({THESIS['frames']}) | ({THESIS['period_s']} s) | "
              f"- | - | \"did not affect framerate\" |\n")
    if a.json:
        Path(a.json).write_text(json.dumps({"size": a.size, "rounds": a.rounds, "runs": runs}, indent=1))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
