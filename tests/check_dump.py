#!/usr/bin/env python3
"""Checks a `cloudbench dump` with NumPy, independently of the C++ code.

For every step folder it checks shapes and dtypes, then recomputes from the
dumped inputs, with NumPy written from SPEC.md alone:
  - q from cld (binomial smoothing, zero outside the grid), bit for bit;
  - D as the column sums of q, tiles and bands from q;
  - the automaton step t -> t+1 from (hum, act, cld, region) at step t,
    including the hash random numbers, bit for bit against step t+1.
Usage: check_dump.py DUMP_DIR STEPS SCENE_JSON
"""
import json
import sys
from pathlib import Path

import numpy as np

M = np.uint64(0xFFFFFFFF)


def lowbias32(x):
    x = x.astype(np.uint64)
    x ^= x >> np.uint64(16)
    x = (x * np.uint64(0x7FEB352D)) & M
    x ^= x >> np.uint64(15)
    x = (x * np.uint64(0x846CA68B)) & M
    x ^= x >> np.uint64(16)
    return x


def rand24(seed, step, stream, v):
    key = lowbias32(np.uint64(seed) ^ lowbias32(np.array([(step * 4 + stream + 0x9E3779B9) & 0xFFFFFFFF])))[0]
    return lowbias32(v.astype(np.uint64) ^ key) >> np.uint64(8)


def quantize(p):
    return int(round(p * 2**24))  # p * 2^24 is exact; ties do not occur for the scenes' p


def shifted(a, d, axis):
    """a(x + d) along axis with zero outside."""
    out = np.zeros_like(a)
    n = a.shape[axis]
    src = [slice(None)] * 3
    dst = [slice(None)] * 3
    if d >= 0:
        src[axis], dst[axis] = slice(d, n), slice(0, max(n - d, 0))
    else:
        src[axis], dst[axis] = slice(0, n + d), slice(-d, n)
    out[tuple(dst)] = a[tuple(src)]
    return out


def smooth(cld, r):
    w = {0: [1], 1: [1, 2, 1], 2: [1, 4, 6, 4, 1]}[r]
    acc = cld.astype(np.int64)
    for axis in range(3):
        acc = sum(w[d + r] * shifted(acc, d, axis) for d in range(-r, r + 1))
    return (acc / float(sum(w) ** 3)).astype(np.float32)


def ca_step(hum, act, cld, region, seed, t, q_ext, q_hum, q_act):
    a = act.astype(bool)
    f = np.zeros_like(a)
    for axis, d in [(2, 1), (2, -1), (2, 2), (2, -2), (1, 1), (1, -1), (1, 2), (1, -2), (0, 1), (0, -1), (0, -2)]:
        f |= shifted(a, d, axis)  # (nz, ny, nx): axis 2 is i, 0 is k
    h, c = hum.astype(bool), cld.astype(bool)
    hum1, cld1, act1 = h & ~a, c | a, ~a & h & f
    v = np.arange(hum.size, dtype=np.uint64).reshape(hum.shape)
    r = region.astype(np.uint64)
    p_ext = ((np.uint64(255) - r) * np.uint64(q_ext) + np.uint64(127)) // np.uint64(255)
    p_hum = (r * np.uint64(q_hum) + np.uint64(127)) // np.uint64(255)
    p_act = (r * np.uint64(q_act) + np.uint64(127)) // np.uint64(255)
    cld2 = cld1 & ~(rand24(seed, t, 0, v) < p_ext)
    hum2 = hum1 | (rand24(seed, t, 1, v) < p_hum)
    act2 = act1 | (rand24(seed, t, 2, v) < p_act)
    cld2 &= region > 0
    return hum2.astype(np.uint8), act2.astype(np.uint8), cld2.astype(np.uint8)


def main():
    root, steps, scene_path = Path(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    scene = json.loads(Path(scene_path).read_text())
    nx, ny, nz = scene["grid"]["size"]
    ca = scene.get("ca", {})
    if any(s != [0, 0] for s in ca.get("wind_shift", [])):
        sys.exit("check_dump.py does not model wind shifts; use a scene without them")
    radius = scene.get("smooth", {}).get("radius", 1)
    tile = scene.get("density", {}).get("tile", 32)
    band = scene.get("density", {}).get("band", 4)
    checked = 0
    for t in range(steps):
        d = root / f"step_{t:04d}"
        arrays = {name: np.load(d / f"{name}.npy") for name in ["hum", "act", "cld", "region", "q", "density", "tiles", "bands"]}
        for name in ["hum", "act", "cld", "region"]:
            assert arrays[name].shape == (nz, ny, nx) and arrays[name].dtype == np.uint8, name
        assert arrays["q"].shape == (nz, ny, nx) and arrays["q"].dtype == np.float32
        assert arrays["density"].shape == (1, ny, nx) and arrays["density"].dtype == np.float32
        for name in ["hum", "act", "cld"]:
            assert set(np.unique(arrays[name])) <= {0, 1}, name
        q = smooth(arrays["cld"], radius)
        assert np.array_equal(q, arrays["q"]), f"step {t}: q differs from NumPy smoothing"
        D = arrays["q"].astype(np.float64).sum(axis=0, keepdims=True).astype(np.float32)
        assert np.array_equal(D, arrays["density"]), f"step {t}: D differs from the column sums"
        ty, tx = -(-ny // tile), -(-nx // tile)
        pad = np.zeros((nz, ty * tile, tx * tile), dtype=np.float32)
        pad[:, :ny, :nx] = arrays["q"]
        tiles = (pad.reshape(nz, ty, tile, tx, tile) > 0).any(axis=(0, 2, 4)).astype(np.uint8)[None]
        assert np.array_equal(tiles, arrays["tiles"]), f"step {t}: tiles differ"
        nb = -(-nz // band)
        padz = np.zeros((nb * band, ty * tile, tx * tile), dtype=np.float32)
        padz[:nz] = pad
        bands = (padz.reshape(nb, band, ty, tile, tx, tile) > 0).any(axis=(1, 3, 5)).astype(np.uint8)
        assert np.array_equal(bands, arrays["bands"]), f"step {t}: bands differ"
        if t + 1 < steps:
            nxt = root / f"step_{t + 1:04d}"
            expected = ca_step(arrays["hum"], arrays["act"], arrays["cld"], arrays["region"], ca.get("seed", 1), t,
                               quantize(ca.get("p_ext", 0.1)), quantize(ca.get("p_hum", 0.1)),
                               quantize(ca.get("p_act", 0.001)))
            for name, e in zip(["hum", "act", "cld"], expected):
                got = np.load(nxt / f"{name}.npy")
                if not np.array_equal(got, e):
                    bad = np.argwhere(got != e)[0]
                    sys.exit(f"step {t}->{t + 1}: {name} differs at (k,j,i)={tuple(bad)}: dump {got[tuple(bad)]}, numpy {e[tuple(bad)]}")
        checked += 1
    print(f"{checked} passed, 0 failed")


if __name__ == "__main__":
    main()
