#!/usr/bin/python3
"""Wang, Ji and Zhang's relighting against shading again: its error and what it saves (SPEC 15).

With `layers.relight` "vector", shade runs once, for the first step's sun s0, and each frame scales that T by
max(0, s0 . s) for its own sun s, where "shade" (the default) shades again whenever the sun moves. This tool
moves the sun of a render_layers scene by a fixed speed, dumps every step's frames both ways with `cloudbench
dump` and prints, per step (the sun's angle from s0) and camera, the relit frame's error against the re-shaded
one: the largest channel difference and the PSNR (peak: the re-shaded frame's largest value). Then it times
both with `cloudbench run` (interleaved, ROUNDS rounds) and prints shade's time per run each way: the saving.

Usage: tools/relight_error.py [--cli build/release/cloudbench] [--scene layers-small] [--steps 8]
       [--elevation 40] [--azimuth 135] [--speed-elevation -2] [--speed-azimuth 6] [--backend cpu]
       [--rounds 3] [--out /tmp/relight] [--json FILE] [--quick]
--quick: 3 steps, 1 round (a smoke test of the script, not a measurement).
"""
import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path
from statistics import median

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
from check_bad_inputs import exr_floats  # noqa: E402  (the pixels, not the header, which holds a time stamp)

MODES = ("shade", "vector")


def sun_sets(a):
    speed = json.dumps({"elevation_deg": a.speed_elevation, "azimuth_deg": a.speed_azimuth})
    return ["--set", f"sun.elevation_deg={a.elevation}", "--set", f"sun.azimuth_deg={a.azimuth}",
            "--set", f"sun.speed={speed}"]


def direction(elevation_deg, azimuth_deg):
    e, z = math.radians(elevation_deg), math.radians(azimuth_deg)
    return (math.cos(e) * math.cos(z), math.cos(e) * math.sin(z), math.sin(e))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/release/cloudbench"))
    ap.add_argument("--scene", default="layers-small")
    ap.add_argument("--steps", type=int, default=8)
    ap.add_argument("--elevation", type=float, default=40)
    ap.add_argument("--azimuth", type=float, default=135)
    ap.add_argument("--speed-elevation", type=float, default=-2)
    ap.add_argument("--speed-azimuth", type=float, default=6)
    ap.add_argument("--backend", default="cpu")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out", default="/tmp/relight")
    ap.add_argument("--json", default=None, help="write the measurements here")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    steps, rounds = (3, 1) if a.quick else (a.steps, a.rounds)
    out = Path(a.out)
    import numpy as np

    for mode in MODES:
        subprocess.run([a.cli, "dump", a.scene, "--backend", a.backend, "--quiet", "--steps", str(steps),
                        "--out", str(out / "dump" / mode), "--set", f'layers.relight="{mode}"'] + sun_sets(a),
                       check=True, stdout=subprocess.DEVNULL)
    s0 = direction(a.elevation, a.azimuth)
    rows = []
    print(f"Scene {a.scene} on {a.backend}: the sun from elevation {a.elevation} deg, azimuth {a.azimuth} deg, "
          f"moving {a.speed_elevation} and {a.speed_azimuth} deg per step.\n")
    print("| step | sun's angle from s0, deg | camera | max abs difference | PSNR, dB |")
    print("|---|---|---|---|---|")
    for t in range(steps):
        s = direction(a.elevation + a.speed_elevation * t, a.azimuth + a.speed_azimuth * t)
        angle = math.degrees(math.acos(max(-1.0, min(1.0, sum(x * y for x, y in zip(s0, s))))))
        folder = {m: out / "dump" / m / f"step_{t:04d}" for m in MODES}
        for frame in sorted(folder["shade"].glob("frame-layers-*.exr")):
            camera = frame.stem[len("frame-layers-"):]
            ref = exr_floats(frame).astype(np.float64)
            got = exr_floats(folder["vector"] / frame.name).astype(np.float64)
            diff = float(np.max(np.abs(got - ref)))
            mse = float(np.mean((got - ref) ** 2))
            peak = float(np.max(ref))
            psnr = math.inf if mse == 0 else 10 * math.log10(peak * peak / mse)
            rows.append({"step": t, "angle_deg": angle, "camera": camera, "max_abs": diff, "psnr_db": psnr})
            print(f"| {t} | {angle:.1f} | {camera} | {diff:.4g} | {psnr:.1f} |")

    shade_ms = {m: [] for m in MODES}
    for _ in range(rounds):
        for mode in MODES:  # interleaved
            folder = out / "run" / mode
            subprocess.run([a.cli, "run", a.scene, "--backend", a.backend, "--quiet", "--out", str(folder),
                            "--steps", str(steps), "--set", "warmup_steps=0", "--set", "render.every_steps=1",
                            "--set", f'layers.relight="{mode}"'] + sun_sets(a), check=True, stdout=subprocess.DEVNULL)
            b = json.loads((folder / "results.json").read_text())["backends"][a.backend]
            shade_ms[mode].append(sum(b["stages"]["shade"]["samples_ms"]))
    print(f"\nshade's time per run of {steps} steps (median [min max] over {rounds} rounds, interleaved):")
    for mode in MODES:
        v = shade_ms[mode]
        print(f"- relight {mode}: {median(v):.2f} [{min(v):.2f} {max(v):.2f}] ms")
    if a.json:
        Path(a.json).write_text(json.dumps({"scene": a.scene, "backend": a.backend, "steps": steps, "rounds": rounds,
                                            "sun": {"elevation_deg": a.elevation, "azimuth_deg": a.azimuth,
                                                    "speed": [a.speed_elevation, a.speed_azimuth]},
                                            "frames": rows, "shade_ms_per_run": shade_ms,
                                            "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}, indent=1))


if __name__ == "__main__":
    main()
