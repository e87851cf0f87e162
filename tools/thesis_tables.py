#!/usr/bin/python3
"""The thesis's Tables 8.2, 8.3 and 8.4 on every backend.

Renders the three thesis scenes (scenes/thesis-low, thesis-medium, thesis-high:
256x256x32, 1024x768, cameras "ground" and "above") with render_splat under
three settings -- no culling, view-frustum culling (VFD, `render.culling`),
and VFD plus empty-space skipping (VFD/ESS, `render.skipping`) -- on each
backend, interleaved (round r: scene, setting, backend innermost), and prints a
Markdown table per backend: the frame rate of render_splat per camera (1000 /
the run's median frame ms) as median [min max] over the rounds, our ratios
VFD/none and VFD+ESS/none, and the thesis's frame rates and ratios beside them
(Fizimayer's thesis, Tables 8.2-8.4, measured on an NVIDIA GeForce 8700M GT). It also
checks that every camera's last image (the EXR) is bit for bit the same under
the three settings per backend and round (culling and skipping change no pixel,
SPEC 8) and exits 1 if not.

The frame rate is that of render_splat alone (the thesis's "rendering"
tables); the simulation steps before the first render (warmup_steps, 100) are
not timed. On lavapipe and llvmpipe the device is this machine's CPU.

Usage: tools/thesis_tables.py [--cli build/release/cloudbench] [--backends cpu,gl,vk]
       [--scenes thesis-low,thesis-medium,thesis-high] [--rounds 3] [--frames 2]
       [--size 1024x768] [--cpu-isa auto] [--out /tmp/thesis-tables] [--json reports/loop/thesis-tables.json]
--frames F renders F frames per camera at the one render step (render.frames_per_step; alpha 1/F .. 1),
so a run's median is over F frames.
"""
import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path
from statistics import median

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
from check_bad_inputs import exr_floats  # noqa: E402  (the pixels, not the header, which holds a time stamp)

SETTINGS = [("none", ["render.culling=false", "render.skipping=false"]),
            ("vfd", ["render.culling=true", "render.skipping=false"]),
            ("vfd_ess", ["render.culling=true", "render.skipping=true"])]
# Fizimayer's thesis, Tables 8.2 (none), 8.3 (VFD), 8.4 (VFD/ESS), fps, NVIDIA GeForce 8700M GT.
THESIS = {"thesis-low": (33, 95, 118), "thesis-medium": (25, 51, 55), "thesis-high": (11, 21, 33)}
THESIS_GPU = "NVIDIA GeForce 8700M GT"


def run_once(cli, scene, backend, overrides, out, warmup, frames, size, cpu_isa):
    args = [cli, "run", scene, "--backend", backend, "--quiet", "--out", str(out), "--cpu-isa", cpu_isa,
            "--set", f"steps={warmup + 1}", "--set", f"warmup_steps={warmup}", "--set", "render.every_steps=1",
            "--set", f"render.frames_per_step={frames}"]
    w, h = size.split("x")
    args += ["--set", f"render.width={w}", "--set", f"render.height={h}"]
    for o in overrides:
        args += ["--set", o]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    b = json.loads((out / "results.json").read_text())["backends"][backend]
    cams = {}
    for cam, f in b["frames"].items():
        cams[cam] = {"median_ms": f["median_ms"], "fps": 1000.0 / f["median_ms"], "samples_ms": f["samples_ms"],
                     "splats": f.get("splats", [None])[-1], "voxels_visited": f.get("voxels_visited", [None])[-1]}
    return {"device": b["device"], "cameras": cams}


def fmt(values):
    return f"{median(values):.1f} [{min(values):.1f} {max(values):.1f}]"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/release/cloudbench"))
    ap.add_argument("--backends", default="cpu,gl,vk")
    ap.add_argument("--scenes", default="thesis-low,thesis-medium,thesis-high")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--warmup", type=int, default=100, help="simulation steps before the one render step")
    ap.add_argument("--frames", type=int, default=2, help="frames per camera per run (render.frames_per_step)")
    ap.add_argument("--size", default="1024x768")
    ap.add_argument("--cpu-isa", default="auto", help="the CPU kernels' SIMD target (cloudbench --cpu-isa)")
    ap.add_argument("--out", default="/tmp/thesis-tables")
    ap.add_argument("--json", default=None, help="write the raw runs here")
    a = ap.parse_args()
    backends, scenes = a.backends.split(","), a.scenes.split(",")
    runs = {b: {s: {k: [] for k, _ in SETTINGS} for s in scenes} for b in backends}
    mismatches, loads, t0 = [], [], time.time()
    for rnd in range(a.rounds):
        for s in scenes:
            for key, overrides in SETTINGS:
                for b in backends:
                    loads.append(os.getloadavg()[0])
                    out = Path(a.out) / b / s / key
                    r = run_once(a.cli, s, b, overrides, out, a.warmup, a.frames, a.size, a.cpu_isa)
                    runs[b][s][key].append(r)
                    print(f"round {rnd} {s} {key} {b}: " + ", ".join(
                        f"{c} {v['fps']:.1f} fps" for c, v in r["cameras"].items()), file=sys.stderr, flush=True)
            for b in backends:  # the three settings' last images, bit for bit, this round
                for cam in runs[b][s]["none"][-1]["cameras"]:
                    name = f"frame-splat-{cam}-{b}.exr"
                    ref = exr_floats(Path(a.out) / b / s / "none" / name)
                    for key in ("vfd", "vfd_ess"):
                        img = exr_floats(Path(a.out) / b / s / key / name)
                        if img.shape != ref.shape or not (img == ref).all():
                            mismatches.append(f"round {rnd} {b} {s} {cam}: {key} differs from none")
    print(f"{a.rounds} interleaved rounds, {a.size}, {a.warmup} warm-up steps then one render step of {a.frames} "
          f"frames per camera; render_splat fps = 1000 / the run's median frame ms, median [min max] over rounds; "
          f"1-minute load {min(loads):.1f}..{max(loads):.1f}; {time.time() - t0:.0f} s in all. "
          f"Thesis: Fizimayer's thesis, Tables 8.2-8.4, {THESIS_GPU}, one figure per scene.\n")
    table = {}
    for b in backends:
        dev = runs[b][scenes[0]]["none"][0]["device"]
        print(f"### {b} ({dev})\n")
        print("| scene | camera | none fps | VFD fps | VFD+ESS fps | VFD/none | VFD+ESS/none | thesis none / VFD / "
              "VFD+ESS fps | thesis VFD/none | thesis VFD+ESS/none | images |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for s in scenes:
            for cam in runs[b][s]["none"][0]["cameras"]:
                fps = {k: [r["cameras"][cam]["fps"] for r in runs[b][s][k]] for k, _ in SETTINGS}
                med = {k: median(v) for k, v in fps.items()}
                th = THESIS.get(s)
                same = not any(f" {b} {s} {cam}:" in m for m in mismatches)
                thesis_cols = (f"{th[0]} / {th[1]} / {th[2]} | {th[1] / th[0]:.2f} | {th[2] / th[0]:.2f}"
                               if th else "- | - | -")
                print(f"| {s} | {cam} | {fmt(fps['none'])} | {fmt(fps['vfd'])} | {fmt(fps['vfd_ess'])} | "
                      f"{med['vfd'] / med['none']:.2f} | {med['vfd_ess'] / med['none']:.2f} | {thesis_cols} | "
                      f"{'identical' if same else 'DIFFER'} |")
                table.setdefault(b, {}).setdefault(s, {})[cam] = {
                    "fps": fps, "median_fps": med, "vfd_over_none": med["vfd"] / med["none"],
                    "vfd_ess_over_none": med["vfd_ess"] / med["none"], "images_identical": same,
                    "voxels_visited": {k: runs[b][s][k][0]["cameras"][cam]["voxels_visited"] for k, _ in SETTINGS},
                    "splats": {k: runs[b][s][k][0]["cameras"][cam]["splats"] for k, _ in SETTINGS}}
        print()
    for m in mismatches:
        print("MISMATCH", m)
    if a.json:
        Path(a.json).write_text(json.dumps({
            "what": "Fizimayer's thesis, Tables 8.2-8.4 on every backend (tools/thesis_tables.py)",
            "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "size": a.size, "rounds": a.rounds,
            "warmup_steps": a.warmup, "frames_per_step": a.frames, "loads": loads,
            "thesis": {"gpu": THESIS_GPU, "fps_none_vfd_vfd_ess": THESIS},
            "settings": dict(SETTINGS), "table": table, "mismatches": mismatches, "runs": runs}, indent=1))
    return 1 if mismatches else 0


if __name__ == "__main__":
    sys.exit(main())
