#!/usr/bin/env python3
"""Checks `cloudbench dump --reference` independently of the C++ code and of Embree.

For every step folder: T_ref.npy is float32 (nz, ny, nx) and shadow_ref.npy
float32 (1, ny, nx), both in [0, 1]; then, from the dumped q alone, a plain 3-D
voxel walk (Amanatides-Woo) written here from docs/contract.md recomputes the optical
depth toward the sun for a random sample of voxels (counted from where the ray
leaves the voxel, docs/accuracy.md) and of ground cells, and compares
exp(-sigma h tau) within 1e-5.
Usage: check_reference.py DUMP_DIR STEPS SCENE_JSON
"""
import json
import math
import sys
from pathlib import Path

import numpy as np


def walk(q, origin, cell, d, t_start):
    """Sum of q * length along origin + t d, t > t_start, from inside voxel `cell`."""
    nz, ny, nx = q.shape
    n = (nx, ny, nz)
    cell = list(cell)
    step, t_max, t_delta = [0] * 3, [math.inf] * 3, [math.inf] * 3
    for a in range(3):
        if d[a] > 0:
            step[a], t_max[a], t_delta[a] = 1, (cell[a] + 1 - origin[a]) / d[a], 1 / d[a]
        elif d[a] < 0:
            step[a], t_max[a], t_delta[a] = -1, (cell[a] - origin[a]) / d[a], -1 / d[a]
    t, total = 0.0, 0.0
    while all(0 <= cell[a] < n[a] for a in range(3)):
        a = min(range(3), key=lambda b: t_max[b])
        length = t_max[a] - max(t, t_start)
        if length > 0:
            total += float(q[cell[2], cell[1], cell[0]]) * length
        t = t_max[a]
        cell[a] += step[a]
        t_max[a] += t_delta[a]
    return total


def main():
    dump, steps, scene_path = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    scene = json.loads(Path(scene_path).read_text())
    el = math.radians(scene.get("sun", {}).get("elevation_deg", 40))
    az = math.radians(scene.get("sun", {}).get("azimuth_deg", 30))
    # The float32 direction every stage uses (SPEC 0).
    s = [float(np.float32(x)) for x in (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))]
    sigma = scene.get("shade", {}).get("sigma", 0.02)
    h = scene["grid"].get("voxel_size", 50.0)
    t_exit = 0.5 / max(abs(x) for x in s)
    rng = np.random.default_rng(1)
    worst = 0.0
    for t in range(steps):
        folder = dump / f"step_{t:04d}"
        q = np.load(folder / "q.npy")
        T = np.load(folder / "T_ref.npy")
        G = np.load(folder / "shadow_ref.npy")
        nz, ny, nx = q.shape
        assert T.dtype == np.float32 and T.shape == (nz, ny, nx), (folder, T.dtype, T.shape)
        assert G.dtype == np.float32 and G.shape == (1, ny, nx), (folder, G.dtype, G.shape)
        assert np.all((T >= 0) & (T <= 1)) and np.all((G >= 0) & (G <= 1)), folder
        for _ in range(300):
            i, j, k = int(rng.integers(nx)), int(rng.integers(ny)), int(rng.integers(nz))
            tau = walk(q, (i + 0.5, j + 0.5, k + 0.5), (i, j, k), s, t_exit)
            err = abs(math.exp(-sigma * h * tau) - float(T[k, j, i]))
            worst = max(worst, err)
            assert err <= 1e-5, f"{folder}: T_ref at (i={i}, j={j}, k={k}): {T[k, j, i]} vs {math.exp(-sigma * h * tau)}"
        for _ in range(100):
            i, j = int(rng.integers(nx)), int(rng.integers(ny))
            tau = walk(q, (i + 0.5, j + 0.5, 0.0), (i, j, 0), s, 0.0) if s[2] > 0 else 0.0
            err = abs(math.exp(-sigma * h * tau) - float(G[0, j, i]))
            worst = max(worst, err)
            assert err <= 1e-5, f"{folder}: shadow_ref at (i={i}, j={j}): {G[0, j, i]} vs {math.exp(-sigma * h * tau)}"
    print(f"T_ref and shadow_ref of {steps} steps match a voxel walk from q (worst |error| {worst:.2e})")


if __name__ == "__main__":
    main()
