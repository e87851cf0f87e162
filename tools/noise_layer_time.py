#!/usr/bin/python3
"""The march CPU time per frame of scenes/noise-layer.json (the 100 ms target), at the
scene's step 0.5 and at Olajos's step 1: 5 interleaved rounds of runs with 1 and 3 frames (static clouds),
march CPU per frame = (CPU(3 frames) - CPU(1 frame)) / 2, so start-up, noise, shade and writing the frame
cancel. Run from the repository root; prints medians [min max]. reports/march/scenes.md has the results."""
import json, resource, subprocess, os
from statistics import median
cli = "build/release/cloudbench"
def run(extra, out):
    b = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([cli, "run", "noise-layer", "--backend", "cpu", "--quiet", "--out", out, "--set", "warmup_steps=0",
                    "--set", "render.every_steps=1"] + extra, check=True, stdout=subprocess.DEVNULL)
    a = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = a.ru_utime - b.ru_utime + a.ru_stime - b.ru_stime
    f = json.load(open(out + "/results.json"))["backends"]["cpu"]["march_frames"]["above"]
    return cpu, f
rows = {k: [] for k in ("s05n1", "s05n3", "s1n1", "s1n3")}
loads = []
for i in range(5):
    loads.append(os.getloadavg()[0])
    rows["s05n1"].append(run(["--set", "steps=1"], "/tmp/sc/nlA"))
    rows["s05n3"].append(run(["--set", "steps=3"], "/tmp/sc/nlB"))
    rows["s1n1"].append(run(["--set", "steps=1", "--set", "march.step=1"], "/tmp/sc/nlC"))
    rows["s1n3"].append(run(["--set", "steps=3", "--set", "march.step=1"], "/tmp/sc/nlD"))
print("loads", ["%.1f" % l for l in loads])
for k in ("s05", "s1"):
    per = [(c3 - c1) / 2 * 1e3 for (c1, _), (c3, _) in zip(rows[k + "n1"], rows[k + "n3"])]
    walls = [w for _, f in rows[k + "n3"] for w in f["samples_ms"]]
    f = rows[k + "n3"][0][1]
    print(k, "march CPU ms/frame median %.0f [%.0f %.0f]" % (median(per), min(per), max(per)),
          "wall ms/frame median %.0f [%.0f %.0f] (15 frames)" % (median(walls), min(walls), max(walls)),
          "samples %d light %d skipped %d" % (f["samples"][-1], f["light_samples"][-1], f["bricks_skipped"][-1]),
          "M samples per CPU-s %.1f" % (f["samples"][-1] / median(per) / 1e3))
