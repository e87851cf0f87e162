#!/usr/bin/env python3
"""Checks placed ellipsoids (SPEC 17) in `cloudbench dump`, with NumPy written from docs/contract.md alone.

Dumps scenes/placed-shapes.json twice on one backend, as it is and with `ellipsoids.placed` emptied (the random
list is the same: placed ellipsoids draw nothing from its generator), and checks at every step that the region is
SPEC 2's maximum over both: max(the random-only dump's region, the placed ellipsoids rasterised here in double from
the scene's centre or keyframes, semi-axes, yaw, start, lifetime or persistent and the list's shrink_steps), within
SPEC 2's rule (|dR| <= 1, at most 0.5 % of voxels differ). Then it runs check_dump.py on the placed dump, which
recomputes the automaton from the dumped region bit for bit.

Usage: check_dump_placed.py CLI OUT_DIR BACKEND
Prints "placed dump checked" on success; exit 4 when the backend cannot start (a skip).
"""
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

STEPS = 8
HERE = Path(__file__).resolve().parent
SCENE = HERE.parent / "scenes" / "placed-shapes.json"


def centre_at(p, t):
    keys = p.get("keyframes")
    if not keys:
        return p["center"]
    if t <= keys[0]["step"]:
        return keys[0]["center"]
    if t >= keys[-1]["step"]:
        return keys[-1]["center"]
    b = next(n for n, k in enumerate(keys) if k["step"] >= t)
    lo, hi = keys[b - 1], keys[b]
    w = (t - lo["step"]) / (hi["step"] - lo["step"])
    return [a + (c - a) * w for a, c in zip(lo["center"], hi["center"])]


def placed_region(scene, t):
    """R of the placed ellipsoids alive at list step t alone (SPEC 2 in double, SPEC 17's life and shrink)."""
    nx, ny, nz = scene["grid"]["size"]
    shrink_steps = scene["ellipsoids"].get("shrink_steps", 40)
    k, j, i = np.meshgrid(np.arange(nz) + 0.5, np.arange(ny) + 0.5, np.arange(nx) + 0.5, indexing="ij")
    best = np.zeros((nz, ny, nx))
    for p in scene["ellipsoids"].get("placed", []):
        start = p.get("start", 0)
        age = t - start
        if age < 0 or ("lifetime" in p and age >= p["lifetime"]):
            continue
        scale = 1.0
        if "lifetime" in p and shrink_steps > 0 and age + shrink_steps > p["lifetime"]:
            scale = (p["lifetime"] - age) / shrink_steps
        a, b, c = (max(s * scale, 1e-3) for s in p["semi_axes"])
        cx, cy, cz = centre_at(p, t)
        yaw = math.radians(p.get("yaw_deg", 0))
        ox, oy, dz = i - cx, j - cy, k - cz
        dx = math.cos(yaw) * ox + math.sin(yaw) * oy
        dy = -math.sin(yaw) * ox + math.cos(yaw) * oy
        rho = np.sqrt((dx / a) ** 2 + (dy / b) ** 2 + (dz / c) ** 2)
        best = np.maximum(best, np.maximum(0.0, 1.0 - rho))
    return np.minimum(255, np.floor(255 * best + 0.5)).astype(np.int32)


def dump(cli, out, backend, sets):
    cmd = [cli, "dump", str(SCENE), "--backend", backend, "--steps", str(STEPS), "--quiet", "--out", str(out)]
    for s in sets:
        cmd += ["--set", s]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode == 4:
        print(f"{backend} unavailable: {run.stderr.strip()}")
        sys.exit(4)
    if run.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: exit {run.returncode}\n{run.stderr}")


def main():
    cli, out, backend = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    scene = json.loads(SCENE.read_text())
    dump(cli, out / "placed", backend, [])
    dump(cli, out / "random", backend, ["ellipsoids.placed=[]"])
    placed_voxels = 0
    for t in range(STEPS):
        got = np.load(out / "placed" / f"step_{t:04d}" / "region.npy").astype(np.int32)
        random = np.load(out / "random" / f"step_{t:04d}" / "region.npy").astype(np.int32)
        mine = placed_region(scene, t)
        expected = np.maximum(random, mine)
        diff = np.abs(got - expected)
        share = np.count_nonzero(diff) / diff.size
        if diff.max() > 1 or share > 0.005:
            bad = np.unravel_index(diff.argmax(), diff.shape)
            sys.exit(f"step {t}: region differs from max(random, placed) at (k,j,i)={bad}: dump {got[bad]}, "
                     f"expected {expected[bad]} (random {random[bad]}, placed {mine[bad]}); {share:.4%} differ")
        placed_voxels += np.count_nonzero(mine > random)
    if placed_voxels < 10000:
        sys.exit(f"only {placed_voxels} voxels where a placed ellipsoid wins: the check needs them")
    check = subprocess.run([sys.executable, str(HERE / "check_dump.py"), str(out / "placed"), str(STEPS), str(SCENE)],
                           capture_output=True, text=True)
    if check.returncode != 0:
        sys.exit(f"check_dump.py on the placed dump: exit {check.returncode}\n{check.stdout}{check.stderr}")
    print(f"placed dump checked: {STEPS} steps, {placed_voxels} voxel-steps won by placed ellipsoids")


if __name__ == "__main__":
    main()
