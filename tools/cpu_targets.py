#!/usr/bin/python3
"""Every CPU stage and every camera's frame on every SIMD target of this CPU.

Runs `cloudbench run SCENE --backend cpu --cpu-isa T` for each target this CPU
runs (and each --baseline binary, with its own default target), interleaved:
round r runs every scene, then every variant. Prints a Markdown table per
scene: each stage's median wall ms over the run's timed steps, and each
camera's median frame ms, as the median [min max] over the rounds.

Usage: tools/cpu_targets.py [--cli build/release/cloudbench] [--scenes thesis-medium,thesis-high]
       [--targets scalar,sse4,avx2,avx512] [--baseline LABEL=BINARY]... [--rounds 3]
       [--threads 2] [--out /tmp/cpu-targets] [--json FILE]
A target this CPU lacks is left out with a note.
"""
import argparse
import json
import subprocess
import sys
from pathlib import Path
from statistics import median

ROOT = Path(__file__).resolve().parent.parent


def run_once(cli, scene, isa, threads, out):
    args = [cli, "run", scene, "--backend", "cpu", "--quiet", "--out", str(out), "--threads", str(threads)]
    if isa:
        args += ["--cpu-isa", isa]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    b = json.loads((out / "results.json").read_text())["backends"]["cpu"]
    row = {stage: s["median_ms"] for stage, s in b["stages"].items()}
    for camera, f in b.get("frames", {}).items():
        row[f"frame {camera}"] = f["median_ms"]
    return b["device"], row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=str(ROOT / "build/release/cloudbench"))
    ap.add_argument("--scenes", default="thesis-medium,thesis-high")
    ap.add_argument("--targets", default="scalar,sse4,avx2,avx512")
    ap.add_argument("--baseline", action="append", default=[], help="LABEL=BINARY, run with its default target")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", default="/tmp/cpu-targets")
    ap.add_argument("--json", default=None, help="write the raw runs here")
    a = ap.parse_args()

    variants = []  # (label, binary, isa)
    for spec in a.baseline:
        label, _, binary = spec.partition("=")
        variants.append((label, binary, None))
    for isa in a.targets.split(","):
        refused = subprocess.run([a.cli, "dump", "ci-small", "--steps", "1", "--cpu-isa", isa, "--out",
                                  str(Path(a.out) / "probe"), "--quiet"], capture_output=True, text=True)
        if refused.returncode == 2:
            print(f"left out: {refused.stderr.strip().splitlines()[0]}")
            continue
        variants.append((isa, a.cli, isa))

    runs = {}  # scene -> label -> list of rows
    devices = {}
    for r in range(a.rounds):
        for scene in a.scenes.split(","):
            for label, binary, isa in variants:
                device, row = run_once(binary, scene, isa, a.threads, Path(a.out) / scene / f"{label}-{r}")
                devices[label] = device
                runs.setdefault(scene, {}).setdefault(label, []).append(row)
    for scene, by_label in runs.items():
        labels = [v[0] for v in variants]
        keys = []
        for rows in by_label.values():
            for row in rows:
                keys += [k for k in row if k not in keys]
        print(f"\n### {scene}: median ms [min max] over {a.rounds} rounds\n")
        print("| | " + " | ".join(labels) + " |")
        print("|---|" + "---:|" * len(labels))
        for k in keys:
            cells = []
            for label in labels:
                xs = [row[k] for row in by_label[label] if k in row]
                cells.append(f"{median(xs):.3f} [{min(xs):.3f} {max(xs):.3f}]" if xs else "-")
            print(f"| {k} | " + " | ".join(cells) + " |")
    print("\n" + "\n".join(f"- {label}: {device}" for label, device in devices.items()))
    if a.json:
        Path(a.json).write_text(json.dumps({"devices": devices, "runs": runs}, indent=1) + "\n")


if __name__ == "__main__":
    main()
