#!/usr/bin/python3
"""Olajos's Tables 3.1-3.4 (seed 001 section 3.2) as ratios on this machine.

Runs scenes/noise-track.json (8 cameras along a test track, 1280x720) on the CPU
backend once per setting, the settings interleaved (A B C ... A B C ...), ROUNDS
rounds, and prints a Markdown table: the frame time averaged over the track's
cameras (Olajos's "average frame time"), as median [min max] over the rounds,
the samples per frame and per second, and the ratios Olajos reports beside his
GTX 680 numbers.

Translation of his settings (docs/performance.md, "The ray-march path"): one of
his texture units is one of our voxels (his texture is 128^3, so is our grid);
his small step of 1 unit is `march.step = 1`; his "large step of 20 units" in
empty space is our brick skipping (bricks of 8 voxels, `march.skipping`); his
adaptive step "starting at 1 unit, growing by 1 unit per unit beyond 100
units" is `march.adaptive` with step 1, start 100, kappa 1 (a gentler kappa
0.05 row is added); his light march on/off is our `march.light` "march"
(n_l = 8) versus "shade" (the shade stage's T, the cheap source: his "off"
had no light at all); phase Mie / HG / none is `phase.function`.

Usage: tools/olajos_tables.py [--cli build/release/cloudbench] [--rounds 5]
       [--out /tmp/olajos] [--json reports/march/olajos-tables.json] [--quick]
--quick renders 320x180 and 1 round (a smoke test of the script, not a measurement).
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
BASE = ["march.step=1", "march.light=shade", "phase.function=henyey-greenstein", "march.skipping.enabled=true"]
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
]

# Olajos's GTX 680 averages (seed 001 Tables 3.1-3.4, ms).
OLAJOS = {
    "skip": (23.728955, 56.155690),  # on, off
    "adaptive": (21.761936, 23.728955),  # on, off
    "light": (23.764996, 12.553803),  # on, off
    "phase": (25.999220, 23.643466, 22.585036),  # Mie, HG, off
}


def run_once(cli, scene, out, overrides, quick):
    args = [cli, "run", scene, "--backend", "cpu", "--quiet", "--out", str(out)]
    for o in BASE + overrides:
        args += ["--set", o]
    if quick:
        args += ["--set", "render.width=320", "--set", "render.height=180"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    r = json.loads((out / "results.json").read_text())
    frames = r["backends"]["cpu"]["march_frames"]
    ms = {cam: f["samples_ms"][-1] for cam, f in frames.items()}
    samples = {cam: f["samples"][-1] for cam, f in frames.items()}
    light = {cam: f["light_samples"][-1] for cam, f in frames.items()}
    return {"ms": ms, "samples": samples, "light_samples": light, "process_cpu_s": cpu_s,
            "stages_ms": {k: v["samples_ms"] for k, v in r["backends"]["cpu"]["stages"].items()}}


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
    a = ap.parse_args()
    rounds = 1 if a.quick else a.rounds
    runs = {k: [] for k, _, _ in SETTINGS}
    loads = []
    for rnd in range(rounds):
        for key, _, overrides in SETTINGS:  # interleaved: every setting once per round
            loads.append(os.getloadavg()[0])
            runs[key].append(run_once(a.cli, a.scene, Path(a.out) / key, overrides, a.quick))
            print(f"round {rnd} {key}: {sum(runs[key][-1]['ms'].values()) / len(runs[key][-1]['ms']):.1f} ms/frame",
                  file=sys.stderr)
    cams = list(runs["base"][0]["ms"].keys())

    def avg_frame(run):  # Olajos's average frame time over the track
        return sum(run["ms"][c] for c in cams) / len(cams)

    def samples_per_frame(run):
        return sum(run["samples"][c] for c in cams) / len(cams)

    avg = {k: [avg_frame(r) for r in v] for k, v in runs.items()}
    med = {k: median(v) for k, v in avg.items()}
    print(f"\nScene {a.scene}, {len(cams)} cameras, {rounds} interleaved rounds; 1-minute load average "
          f"{min(loads):.1f}..{max(loads):.1f} during the runs.\n")
    print("| setting | ms/frame, track average: median [min max] | M samples/frame | M light samples/frame "
          "| M samples/s (wall) | process CPU s/run |")
    print("|---|---|---|---|---|---|")
    for key, label, _ in SETTINGS:
        rs = runs[key]
        spf = median(samples_per_frame(r) for r in rs)
        lpf = median(sum(r["light_samples"][c] for c in cams) / len(cams) for r in rs)
        print(f"| {label} | {fmt(avg[key])} | {spf / 1e6:.2f} | {lpf / 1e6:.2f} | {spf / med[key] / 1e3:.1f} | "
              f"{median(r['process_cpu_s'] for r in rs):.2f} |")
    print("\nPer camera, base row, median ms: " +
          ", ".join(f"{c} {median(r['ms'][c] for r in runs['base']):.0f}" for c in cams))
    o = OLAJOS
    print("\n| table | ours (ms) | ratio | Olajos, GTX 680 (ms) | his ratio |")
    print("|---|---|---|---|---|")
    print(f"| 3.1 skip structure off / on | {med['skip_off']:.0f} / {med['base']:.0f} | "
          f"{med['skip_off'] / med['base']:.2f} | {o['skip'][1]:.1f} / {o['skip'][0]:.1f} | {o['skip'][1] / o['skip'][0]:.2f} |")
    for key in ("adaptive", "adaptive_gentle"):
        print(f"| 3.2 adaptive on / off ({'kappa 1' if key == 'adaptive' else 'kappa 0.05'}) | {med[key]:.0f} / "
              f"{med['base']:.0f} | {med[key] / med['base']:.2f} | {o['adaptive'][0]:.1f} / {o['adaptive'][1]:.1f} | "
              f"{o['adaptive'][0] / o['adaptive'][1]:.2f} |")
    print(f"| 3.3 light march on / off (ours: march / shade) | {med['light_march']:.0f} / {med['base']:.0f} | "
          f"{med['light_march'] / med['base']:.2f} | {o['light'][0]:.1f} / {o['light'][1]:.1f} | "
          f"{o['light'][0] / o['light'][1]:.2f} |")
    print(f"| 3.4 phase Mie / HG / none | {med['mie']:.0f} / {med['base']:.0f} / {med['none']:.0f} | "
          f"{med['mie'] / med['base']:.2f} / 1 / {med['none'] / med['base']:.2f} | {o['phase'][0]:.1f} / "
          f"{o['phase'][1]:.1f} / {o['phase'][2]:.1f} | {o['phase'][0] / o['phase'][1]:.2f} / 1 / "
          f"{o['phase'][2] / o['phase'][1]:.2f} |")
    if a.json:
        Path(a.json).write_text(json.dumps({"scene": a.scene, "rounds": rounds, "loads": loads, "base": BASE,
                                            "settings": {k: ov for k, _, ov in SETTINGS}, "runs": runs,
                                            "when": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}, indent=1))


if __name__ == "__main__":
    main()
