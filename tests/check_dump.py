#!/usr/bin/env python3
"""Checks a `cloudbench dump` with NumPy, independently of the C++ code.

For every step folder it checks shapes and dtypes, then recomputes from the
dumped inputs, with NumPy written from docs/contract.md alone:
  - q from cld (binomial smoothing, zero outside the grid), bit for bit;
  - D as the column sums of q, tiles and bands from q;
  - the automaton step t -> t+1 from (hum, act, cld, region) at step t,
    including the hash random numbers, bit for bit against step t+1;
  - T from q by inverse shear-warp (beer, bilinear, fp32, resolution 1, no
    scattering) within SPEC's 1e-5, and the ground shadow G from D within 1e-5,
    when the dump has them.
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


def shade(q, sun, sigma, h):
    """SPEC 6, beer / bilinear / fp32 / f = 1, in float64. q has shape (nz, ny, nx)."""
    s = np.asarray(sun, dtype=np.float64)
    a = np.abs(s)
    w = 2 if a[2] >= max(a[0], a[1]) else (1 if a[1] >= a[0] else 0)
    u, v = [x for x in range(3) if x != w]
    # Volume as [x, y, z] so that axis numbers are x=0, y=1, z=2.
    vol = np.transpose(q.astype(np.float64), (2, 1, 0))
    vol = np.moveaxis(vol, (u, v, w), (0, 1, 2))  # [u, v, w]
    nu, nv, nw = vol.shape
    du, dv = s[u] / abs(s[w]), s[v] / abs(s[w])
    iu, iv = int(np.floor(du)), int(np.floor(dv))
    fu, fv = du - iu, dv - iv
    order = range(nw - 1, -1, -1) if s[w] > 0 else range(nw)
    T = np.ones_like(vol)

    def sample(slice2d, fill):
        p = np.full((nu + 4, nv + 4), fill)
        p[1:nu + 1, 1:nv + 1] = slice2d
        t00 = p[1 + iu:1 + iu + nu, 1 + iv:1 + iv + nv]
        t10 = p[2 + iu:2 + iu + nu, 1 + iv:1 + iv + nv]
        t01 = p[1 + iu:1 + iu + nu, 2 + iv:2 + iv + nv]
        t11 = p[2 + iu:2 + iu + nu, 2 + iv:2 + iv + nv]
        return (t00 * (1 - fu) + t10 * fu) * (1 - fv) + (t01 * (1 - fu) + t11 * fu) * fv

    prev = None
    for m, k in enumerate(order):
        if m > 0:
            T[:, :, k] = sample(T[:, :, prev], 1.0) * np.exp(-sigma * h * sample(vol[:, :, prev], 0.0) / abs(s[w]))
        prev = k
    T = np.moveaxis(T, (0, 1, 2), (u, v, w))
    return np.transpose(T, (2, 1, 0))


def ground_shadow(D, sun, sigma, h, nz):
    """SPEC 7, beer form. D has shape (1, ny, nx)."""
    s = np.asarray(sun, dtype=np.float64)
    ny, nx = D.shape[1:]
    if s[2] <= 0:
        return np.ones_like(D)
    ox, oy = s[0] * nz / (2 * s[2]), s[1] * nz / (2 * s[2])
    j, i = np.mgrid[0:ny, 0:nx]
    x, y = i + ox, j + oy
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = x - x0, y - y0

    def tap(a, b):
        inside = (a >= 0) & (a < nx) & (b >= 0) & (b < ny)
        return np.where(inside, D[0][np.clip(b, 0, ny - 1), np.clip(a, 0, nx - 1)], 0.0)

    d = (tap(x0, y0) * (1 - fx) + tap(x0 + 1, y0) * fx) * (1 - fy) + (tap(x0, y0 + 1) * (1 - fx) + tap(x0 + 1, y0 + 1) * fx) * fy
    return np.exp(-sigma * h * d / s[2])[None]


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
    sun_cfg = scene.get("sun", {})
    el, az = np.radians(sun_cfg.get("elevation_deg", 40)), np.radians(sun_cfg.get("azimuth_deg", 30))
    sun = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], dtype=np.float32)
    shade_cfg = scene.get("shade", {})
    sigma, h = shade_cfg.get("sigma", 0.02), scene["grid"].get("voxel_size", 50.0)
    plain_shade = (shade_cfg.get("attenuation", "beer") == "beer" and shade_cfg.get("filter", "bilinear") == "bilinear"
                   and shade_cfg.get("storage", "fp32") == "fp32" and shade_cfg.get("resolution", 1) == 1
                   and not shade_cfg.get("scattering", {}).get("enabled", False))
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
        if (d / "T.npy").exists() and plain_shade:
            T = np.load(d / "T.npy")
            assert T.shape == (nz, ny, nx) and T.dtype == np.float32
            err = np.abs(T.astype(np.float64) - shade(arrays["q"], sun.astype(np.float64), sigma, h))
            assert err.max() <= 1e-5, f"step {t}: T differs from NumPy shear-warp by {err.max():.3g} at (k,j,i)={np.unravel_index(err.argmax(), err.shape)}"
        if (d / "shadow.npy").exists() and scene.get("shadow", {}).get("form", "beer") == "beer":
            G = np.load(d / "shadow.npy")
            assert G.shape == (1, ny, nx) and G.dtype == np.float32
            err = np.abs(G.astype(np.float64) - ground_shadow(arrays["density"].astype(np.float64), sun.astype(np.float64), sigma, h, nz))
            assert err.max() <= 1e-5, f"step {t}: shadow differs from NumPy by {err.max():.3g}"
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
