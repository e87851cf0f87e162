#!/usr/bin/python3
"""Checks what `cloudbench run` prints beside results.json (docs/cli.md, "run").

frames: runs wang-20km on the CPU at a small size (3 cameras, 3 rendering steps after one warm-up step) and
works each renderer's time per camera frame by hand from results.json's own samples and the scene file's
cameras: median(samples_ms) / cameras. `run`'s line and `report`'s row must give it (to their 3 decimals), beside
Wang, Ji and Zhang's 2.564 ms; the table lists noise before shade (the order a step runs them) and prints "-"
for noise, which runs only in the warm-up step.

quiet: a short run prints its progress end line on stderr ("cpu: N steps in ..."), and none with --quiet.

usage: check_run_output.py CLOUDBENCH OUT_DIR frames|quiet
"""
import json
import os
import re
import shutil
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SMALL = ["--set", "render.width=160", "--set", "render.height=128", "--set", "grid.size=[32,32,8]"]


def fail(message):
    sys.exit("check_run_output: " + message)


def run(args):
    p = subprocess.run(args, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        fail(f"{' '.join(args)} exited {p.returncode}:\n{p.stdout}\n{p.stderr}")
    return p


def check_frames(cli, out):
    p = run([cli, "run", "wang-20km", "--backend", "cpu", "--quiet", "--out", out, "--set", "steps=4",
             "--set", "warmup_steps=1", "--set", "render.every_steps=1"] + SMALL)
    doc = json.load(open(os.path.join(out, "results.json")))
    cameras = len(json.load(open(os.path.join(ROOT, "scenes", "wang-20km.json")))["render"]["cameras"])
    samples = doc["backends"]["cpu"]["stages"]["render_layers"]["samples_ms"]
    if cameras != 3 or len(samples) != 3:
        fail(f"expected 3 cameras and 3 samples, got {cameras} and {samples}")
    expected = statistics.median(samples) / cameras
    printed = re.search(r"render_layers per camera frame: ([0-9.]+) ms[^\n]*", p.stdout)
    if not printed:
        fail("run printed no time per camera frame:\n" + p.stdout)
    if abs(float(printed.group(1)) - expected) > 0.0005 + 1e-9:
        fail(f"run: {printed.group(1)} ms per camera frame, expected {expected:.4f} (median of {samples} / {cameras})")
    if "2.564 ms (seed 002" not in printed.group(0):
        fail("run's line lacks Wang, Ji and Zhang's figure: " + printed.group(0))
    rows = [line.split() for line in p.stdout.splitlines() if line.startswith("  ")]
    names = [r[0] for r in rows if r]
    if "noise" not in names or "shade" not in names or names.index("noise") > names.index("shade"):
        fail("the table does not list noise before shade:\n" + p.stdout)
    noise = rows[names.index("noise")]
    if noise[1:6] != ["-"] * 5:
        fail(f"noise has no sample after warm-up and should print '-': {noise}")

    page = os.path.join(out, "report.html")
    run([cli, "report", os.path.join(out, "results.json"), "-o", page])
    html = open(page).read()
    cell = re.search(r"<tr><td[^>]*>render_layers per camera frame</td><td[^>]*>([0-9.]+)</td>(.*?)</tr>", html)
    if not cell:
        fail("report has no render_layers per camera frame row")
    if abs(float(cell.group(1)) - expected) > 0.0005 + 1e-9:
        fail(f"report: {cell.group(1)} ms per camera frame, expected {expected:.4f}")
    if "2.564 ms" not in cell.group(2):
        fail("report's per-frame row lacks the paper's figure: " + cell.group(2))
    print(f"per camera frame {expected:.3f} ms = median {statistics.median(samples):.3f} / {cameras}: run and report")


def check_quiet(cli, out):
    args = [cli, "run", "ci-small", "--backend", "cpu", "--set", "steps=3", "--set", "warmup_steps=1"]
    loud = run(args + ["--out", out + "/loud"])
    if not re.search(r"(^|\r)cpu: 3 steps in [0-9.]+ s", loud.stderr, re.M):
        fail("no end line on stderr without --quiet:\n" + loud.stderr)
    quiet = run(args + ["--out", out + "/quiet", "--quiet"])
    if re.search(r"cpu: (step|[0-9]+ steps|stopped)", quiet.stderr):
        fail("--quiet printed progress:\n" + quiet.stderr)
    print("progress: end line without --quiet, none with it")


def main():
    if len(sys.argv) != 4 or sys.argv[3] not in ("frames", "quiet"):
        sys.exit(__doc__)
    cli, out, mode = sys.argv[1:]
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    check_frames(cli, out) if mode == "frames" else check_quiet(cli, out)


if __name__ == "__main__":
    main()
