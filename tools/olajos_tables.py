#!/usr/bin/python3
"""Olajos's Tables 3.1-3.4 (Olajos's thesis, section 3.2) as ratios on this machine.

Runs scenes/noise-track.json (8 cameras along a test track, 1280x720) on the CPU
backend once per setting, the settings interleaved (A B C ... A B C ...), ROUNDS
rounds, and prints a Markdown table: the frame time averaged over the track's
cameras (Olajos's "average frame time"), as median [min max] over the rounds,
the samples per frame and per second, and the ratios Olajos reports beside his
GTX 680 numbers. Wall times swing with the machine's load; the march's CPU time
per frame (process CPU time less a fixed part priced by a 1-frame run, see
cpu_frame) is the stable figure.

Translation of his settings (docs/performance.md, "The ray-march path"): one of
his texture units is one of our voxels (his texture is 128^3, so is our grid);
his small step of 1 unit is `march.step = 1`; his "large step of 20 units" in
empty space is our brick skipping (bricks of 8 voxels, `march.skipping`); his
adaptive step "starting at 1 unit, growing by 1 unit per unit beyond 100
units" is `march.adaptive` with step 1, start 100, kappa 1 (a gentler kappa
0.05 row is added); his light march on/off is our `march.light` "march"
(n_l = 8) versus "shade" (the shade stage's T, the cheap source: his "off"
had no light at all); phase Mie / HG / none is `phase.function`.

With --backends cpu,vk,gl every setting runs on each backend, interleaved
(round r: A on cpu, vk, gl, then B ...), and the tables come per backend; on
lavapipe and llvmpipe the device is this machine's CPU, so the process CPU
time prices their march the same way. --size WxH renders smaller frames (the
ratios are what Olajos's tables compare).

Usage: tools/olajos_tables.py [--cli build/release/cloudbench] [--rounds 5]
       [--backends cpu] [--size 1280x720]
       [--out /tmp/olajos] [--json reports/march/olajos-tables.json] [--quick]
--quick renders 320x180 of a 32^3 grid, 1 round (a smoke test of the script, not a measurement).
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path
from statistics import median

ROOT = Path(__file__).resolve().parent.parent

# (key, label, overrides). The base row is key "base".
BASE = ["march.step=1", "march.light=shade", "phase.function=henyey-greenstein", "march.skipping.enabled=true",
        "warmup_steps=0", "render.every_steps=1"]
SETTINGS = [
    ("base", "skip on, fixed step 1, light shade, HG (base)", []),
    ("skip_off", "skip structure off", ["march.skipping.enabled=false"]),
    ("adaptive", "adaptive step (1 + 1*max(0, t-100))", ["march.adaptive.enabled=true", "march.adaptive.start=100",
                                                         "march.adaptive.kappa=1"]),
    ("adaptive_gentle", "adaptive step (1 + 0.05*max(0, t-100))",
     ["march.adaptive.enabled=true", "march.adaptive.start=100", "march.adaptive.kappa=0.05"]),
    ("light_march", "light march n_l = 8", ["march.light=march", "march.light_steps=8"]),
    ("mie", "phase Mie", ["phase.function=mie"]),
    ("none", "phase none", ["phase.function=none"]),
    # Not a table row: the base setting with one frame per camera instead of FRAMES. Every run
    # writes each camera's last frame (EXR and PNG, zlib: about a fifth of a run's CPU time), starts
    # up and forms the noise once; the difference to the base row is FRAMES - 1 frames of march
    # alone, which prices that fixed part (see cpu_frame below).
    ("once", "(base, one frame per camera)", ["steps=1"]),
]
FRAMES = 2  # frames per camera per run: a static scene renders the same march every step

# Olajos's GTX 680 averages (Olajos's thesis, Tables 3.1-3.4, ms).
OLAJOS = {
    "skip": (23.728955, 56.155690),  # on, off
    "adaptive": (21.761936, 23.728955),  # on, off
    "light": (23.764996, 12.553803),  # on, off
    "phase": (25.999220, 23.643466, 22.585036),  # Mie, HG, off
}


def run_once(cli, scene, out, overrides, quick, backend, size):
    args = [cli, "run", scene, "--backend", backend, "--quiet", "--out", str(out)]
    for o in BASE + [f"steps={FRAMES}"] + overrides:
        args += ["--set", o]
    if size:
        w, h = size.split("x")
        args += ["--set", f"render.width={w}", "--set", f"render.height={h}"]
    if quick:
        args += ["--set", "render.width=320", "--set", "render.height=180", "--set", "grid.size=[32,32,32]"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    r = json.loads((out / "results.json").read_text())
    frames = r["backends"][backend].get("march_frames", {})
    ms = {cam: median(f["samples_ms"]) for cam, f in frames.items()}
    samples = {cam: f["samples"][-1] for cam, f in frames.items()}
    light = {cam: f["light_samples"][-1] for cam, f in frames.items()}
    return {"ms": ms, "samples": samples, "light_samples": light, "process_cpu_s": cpu_s,
            "stages_ms": {k: v["samples_ms"] for k, v in r["backends"][backend]["stages"].items()}}


def fmt(values):
    return f"{median(values):.0f} [{min(values):.0f} {max(values):.0f}]"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/release/cloudbench"))
    ap.add_argument("--scene", default="noise-track")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--out", default="/tmp/olajos-tables")
    ap.add_argument("--json", default=None, help="write the raw runs here")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--backends", default="cpu", help="comma-separated: cpu,vk,gl")
    ap.add_argument("--size", default="", help="WxH instead of the scene's 1280x720")
    a = ap.parse_args()
    rounds = 1 if a.quick else a.rounds
    backends = a.backends.split(",")
    all_runs = {b: {k: [] for k, _, _ in SETTINGS} for b in backends}
    loads = []
    for rnd in range(rounds):
        for key, _, overrides in SETTINGS:  # interleaved: every setting once per round, on each backend
            for b in backends:
                loads.append(os.getloadavg()[0])
                all_runs[b][key].append(
                    run_once(a.cli, a.scene, Path(a.out) / b / key, overrides, a.quick, b, a.size))
                ms = all_runs[b][key][-1]["ms"]
                print(f"round {rnd} {b} {key}: {sum(ms.values()) / max(len(ms), 1):.1f} ms/frame, "
                      f"{all_runs[b][key][-1]['process_cpu_s']:.2f} CPU s", file=sys.stderr)
    for b in backends:
        print(f"\n## Backend {b}" + (f", {a.size}" if a.size else ""))
        report(a, b, all_runs[b], rounds, loads)
    if a.json:
        Path(a.json).write_text(json.dumps({"scene": a.scene, "rounds": rounds, "loads": loads, "base": BASE,
                                            "size": a.size, "backends": backends,
                                            "settings": {k: ov for k, _, ov in SETTINGS}, "runs": all_runs,
                                            "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}, indent=1))


def report(a, backend, runs, rounds, loads):
    runs = dict(runs)
    cams = list(runs["base"][0]["ms"].keys())
    # Fixed CPU per run (start-up, noise, shade, writing the frames): once = fixed + 1 march of the track,
    # base = fixed + FRAMES marches, so fixed = once - (base - once) / (FRAMES - 1).
    once = median(r["process_cpu_s"] for r in runs.pop("once"))
    base_cpu = median(r["process_cpu_s"] for r in runs["base"])
    fixed_cpu = once - (base_cpu - once) / (FRAMES - 1)

    def cpu_frame(run):  # the march's CPU ms per frame (both threads), averaged over the track's cameras
        return (run["process_cpu_s"] - fixed_cpu) * 1e3 / (FRAMES * len(cams))

    def avg_frame(run):  # Olajos's average frame time over the track
        return sum(run["ms"][c] for c in cams) / len(cams)

    def samples_per_frame(run):
        return sum(run["samples"][c] for c in cams) / len(cams)

    avg = {k: [avg_frame(r) for r in v] for k, v in runs.items()}
    med = {k: median(v) for k, v in avg.items()}
    print(f"\nScene {a.scene}, {len(cams)} cameras, {rounds} interleaved rounds; 1-minute load average "
          f"{min(loads):.1f}..{max(loads):.1f} during the runs.\n")
    print("| setting | wall ms/frame, track average: median [min max] | march CPU ms/frame | M samples/frame "
          "| M light samples/frame | M samples/s (wall) | M samples per CPU-s |")
    print("|---|---|---|---|---|---|---|")
    for key, label, _ in SETTINGS:
        if key == "once":
            continue
        rs = runs[key]
        spf = median(samples_per_frame(r) for r in rs)
        lpf = median(sum(r["light_samples"][c] for c in cams) / len(cams) for r in rs)
        cpu = [cpu_frame(r) for r in rs]
        print(f"| {label} | {fmt(avg[key])} | {fmt(cpu)} | {spf / 1e6:.2f} | {lpf / 1e6:.2f} | "
              f"{spf / med[key] / 1e3:.1f} | {spf / median(cpu) / 1e3:.1f} |")
    print("\nPer camera, base row, median ms: " +
          ", ".join(f"{c} {median(r['ms'][c] for r in runs['base']):.0f}" for c in cams))
    o = OLAJOS
    print(f"\n(Fixed CPU per run, start-up, noise, shade and writing {len(cams)} EXR + PNG frames: "
          f"{fixed_cpu:.2f} s, subtracted; {FRAMES} frames per camera per run.)")
    medc = {k: median(cpu_frame(r) for r in v) for k, v in runs.items()}
    print("\nRatios (wall: medians of the track-average frame time; CPU: of the march's CPU time per frame):")
    print("\n| table | ours, wall ms | ratio (wall) | ours, CPU ms | ratio (CPU) | Olajos, GTX 680 ms | his ratio |")
    print("|---|---|---|---|---|---|---|")
    o = OLAJOS

    def row(title, keys, his):
        wall = " / ".join(f"{med[k]:.0f}" for k in keys)
        cpu = " / ".join(f"{medc[k]:.0f}" for k in keys)
        rw = " / ".join(f"{med[k] / med[keys[-1]]:.2f}" for k in keys[:-1])
        rc = " / ".join(f"{medc[k] / medc[keys[-1]]:.2f}" for k in keys[:-1])
        hs = " / ".join(f"{v:.1f}" for v in his)
        hr = " / ".join(f"{v / his[-1]:.2f}" for v in his[:-1])
        print(f"| {title} | {wall} | {rw} | {cpu} | {rc} | {hs} | {hr} |")

    row("3.1 skip structure off / on", ["skip_off", "base"], [o["skip"][1], o["skip"][0]])
    row("3.2 adaptive on (kappa 1) / off", ["adaptive", "base"], list(o["adaptive"]))
    row("3.2 adaptive on (kappa 0.05) / off", ["adaptive_gentle", "base"], list(o["adaptive"]))
    row("3.3 light march on / off (ours: march / shade)", ["light_march", "base"], list(o["light"]))
    row("3.4 phase Mie / none / HG", ["mie", "none", "base"], [o["phase"][0], o["phase"][2], o["phase"][1]])


if __name__ == "__main__":
    main()
