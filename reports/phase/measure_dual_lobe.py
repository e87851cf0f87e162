#!/usr/bin/python3
"""Angular error of the analytic phase functions against the project's Mie table (kMieCloudTable).

Reads the table the build generates (build/release/core/generated/MieTable.cpp; pass another path as the first
argument), evaluates each phase function in double at the table's 1801 angles (0.1 degree apart) and prints, per
function, the relative error |P - P_mie| / P_mie: its largest value and its RMS over the angles (uniform in theta)
and over the sphere (weighted by sin theta, as the light a sample scatters is), over all angles and outside the
forward peak (theta >= 5 degrees). Also fits the dual lobe's three numbers to the table (least squares of
log P over the sphere) to show what the form can reach at best. Used by reports/phase/dual-lobe.md.
"""
import math
import re
import sys

import numpy as np

path = sys.argv[1] if len(sys.argv) > 1 else "build/release/core/generated/MieTable.cpp"
text = open(path).read()
body = text[text.index("{", text.index("kMieCloudValues")) + 1:text.index("};")]
mie = np.array([float(v.rstrip("f")) for v in re.findall(r"[-+0-9.eE]+f?", body)])
assert mie.size == 1801, mie.size
theta = np.linspace(0.0, math.pi, mie.size)
c = np.cos(theta)
w_sphere = np.sin(theta)
w_sphere[[0, -1]] = 0  # no area at the poles


def hg(g, x=c):
    return (1 - g * g) / (1 + g * g - 2 * g * x) ** 1.5


def cs(g, x=c):
    return 1.5 * (1 - g * g) / (2 + g * g) * (1 + x * x) / (1 + g * g - 2 * g * x) ** 1.5


def dual(gf, gb, w, x=c):
    return (1 - w) * hg(gf, x) + w * hg(gb, x)


def stats(p):
    rel = np.abs(p - mie) / mie
    out = {"log": math.sqrt(np.sum(w_sphere * np.log(p / mie) ** 2) / np.sum(w_sphere)),
           "cone10": cone(p, 10)}
    for name, mask in (("all", np.ones_like(theta, bool)), ("5deg+", theta >= math.radians(5))):
        r = rel[mask]
        ws = w_sphere[mask]
        out[name] = (r.max(), math.degrees(theta[mask][r.argmax()]), math.sqrt(np.mean(r * r)),
                     math.sqrt(np.sum(ws * r * r) / np.sum(ws)))
    return out


def cone(p, deg):  # the share of the scattered light within `deg` of forward
    m = theta <= math.radians(deg)
    return 0.5 * np.trapz((p * np.sin(theta))[m], theta[m]) / norm(p)


def norm(p):  # (1/2) integral of P over cos, trapezoid in theta with sin weight
    return 0.5 * np.trapz(p * np.sin(theta), theta)


rows = [
    ("henyey-greenstein g 0.6 (the scene default)", hg(0.6)),
    ("henyey-greenstein g 0.864 (Mie's asymmetry)", hg(0.86403528)),
    ("cornette-shanks g 0.6", cs(0.6)),
    ("cornette-shanks g 0.864", cs(0.86403528)),
    ("dual-lobe 0.8 / -0.5 / 0.5 (default)", dual(0.8, -0.5, 0.5)),
    ("dual-lobe 0.5 / -0.5 / 0.5", dual(0.5, -0.5, 0.5)),
    ("dual-lobe 0.85 / -0.3 / 0.2", dual(0.85, -0.3, 0.2)),
    ("dual-lobe 0.7 / -0.25 / 0.3", dual(0.7, -0.25, 0.3)),
]


def fit():
    # Least squares of log P over the sphere (sin-weighted), a grid then a local refinement.
    logm = np.log(mie)

    def cost(gf, gb, w):
        d = np.log(dual(gf, gb, w)) - logm
        return np.sum(w_sphere * d * d) / np.sum(w_sphere)

    best = None
    for gf in np.arange(0.50, 0.991, 0.01):
        for gb in np.arange(-0.90, 0.001, 0.02):
            for w in np.arange(0.0, 1.001, 0.02):
                v = cost(gf, gb, w)
                if best is None or v < best[0]:
                    best = (v, gf, gb, w)
    v, gf, gb, w = best
    step = [0.005, 0.01, 0.01]
    for _ in range(60):
        improved = False
        for k in range(3):
            for s in (-1, 1):
                p = [gf, gb, w]
                p[k] += s * step[k]
                p[0] = min(max(p[0], 0), 0.995)
                p[1] = min(max(p[1], -0.995), 0)
                p[2] = min(max(p[2], 0), 1)
                nv = cost(*p)
                if nv < v:
                    v, (gf, gb, w), improved = nv, p, True
        if not improved:
            step = [s / 2 for s in step]
    return gf, gb, w


gf, gb, w = fit()
rows.append(("dual-lobe %.3f / %.3f / %.3f (fit: log P, over the sphere)" % (gf, gb, w), dual(gf, gb, w)))

print("Mie table: %d angles, P(0) %.1f, P(180) %.3f, min %.4f" % (mie.size, mie[0], mie[-1], mie.min()))
print("| phase | P(0) | P(90) | P(180) | mean over sphere | max rel. error (at) | RMS over theta | RMS over sphere "
      "| max, 5-180 deg (at) | RMS over sphere, 5-180 deg | RMS of ln(P / P_mie) over sphere | light within 10 deg |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
print("| mie (the table) | %.1f | %.4f | %.3f | %.6f | | | | | | | %.3f |" % (mie[0], mie[900], mie[-1], norm(mie),
                                                                   cone(mie, 10)))
for name, p in rows:
    s = stats(p)
    a, f = s["all"], s["5deg+"]
    print("| %s | %.2f | %.4f | %.3f | %.6f | %.3g (%.1f deg) | %.3g | %.3g | %.3g (%.1f deg) | %.3g | %.3g | %.3f |" % (
        name, p[0], p[900], p[-1], norm(p), a[0], a[1], a[2], a[3], f[0], f[1], f[3], s["log"], s["cone10"]))
