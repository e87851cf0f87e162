// The ray-march renderer's algorithm (SPEC 10): ray generation, the box and
// near/far clip, the step schedule, trilinear sampling, the light march, the
// point light, the tone map, and ONE per-ray kernel, MarchRay, shared by the
// CPU backend and the exact reference render (which passes its own light
// functor). Decisions where SPEC is silent: docs/pipeline.md, "Ray-march
// renderer" and "Lightning".
//
// Everything inside a ray works in VOXEL units: a point p has world position
// origin + h p, voxel (i, j, k) fills [i, i+1] x [j, j+1] x [k, k+1], and the
// distance t along a ray is in voxel edges (metres = h t). The per-sample code
// is scalar float without the standard library's containers, so the GLSL ports
// can twin it line by line.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/math/Camera.h"
#include "core/math/Grid.h"
#include "core/math/Light.h"
#include "core/math/Random.h"
#include "core/math/Shading.h"

namespace cb {

// ---- Small vector helpers (GLSL has them built in) ------------------------------

inline Vec3 MarchAdd(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 MarchScale(const Vec3& a, float s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline Vec3 MarchAlong(const Vec3& o, const Vec3& d, float t) {
    return {o[0] + d[0] * t, o[1] + d[1] * t, o[2] + d[2] * t};
}
inline float MarchDot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// ---- Rays ------------------------------------------------------------------------

// A ray in voxel units: origin o (the eye), unit direction d, and the part
// [tMin, tMax] that lies inside the volume's box and between the near and far
// planes. Empty when tMin >= tMax.
struct MarchRayGeometry {
    Vec3 origin{}, dir{};
    float tMin = 0, tMax = 0;
    bool Empty() const { return !(tMin < tMax); }
};

// Direction of the ray through the centre of pixel (x, y), row 0 at the top
// (SPEC 8's projection inverted), and cos of its angle to the view axis.
struct PixelDirection {
    Vec3 dir;
    float cosForward;
};
inline PixelDirection PixelRayDirection(const CameraFrame& c, uint32_t x, uint32_t y) {
    const float u = (float(x) + 0.5f - 0.5f * float(c.width)) / c.focalPx;
    const float v = (0.5f * float(c.height) - (float(y) + 0.5f)) / c.focalPx;
    Vec3 d;
    for (int i = 0; i < 3; ++i) d[i] = c.forward[i] + u * c.right[i] + v * c.upVector[i];
    const float inv = 1.0f / std::sqrt(MarchDot(d, d));  // |d| >= 1: forward, right, up are orthonormal
    return {MarchScale(d, inv), inv};
}

// Clips [tMin, tMax] of the ray o + t d to the slab [0, size[a]] of axis a. A
// direction component of (nearly) zero keeps the interval when o lies inside
// that slab and empties it otherwise, so no 0 * inf is ever formed.
inline void ClipRayToSlab(const Vec3& o, const Vec3& d, const Vec3& size, int a, float& tMin, float& tMax) {
    if (std::fabs(d[a]) < 1e-20f) {
        if (o[a] < 0.0f || o[a] > size[a]) tMax = tMin = 0.0f;
        return;
    }
    const float inv = 1.0f / d[a];
    float t0 = (0.0f - o[a]) * inv, t1 = (size[a] - o[a]) * inv;
    if (t0 > t1) std::swap(t0, t1);
    tMin = std::max(tMin, t0);
    tMax = std::min(tMax, t1);
}

// Clips [tMin, tMax] of the ray o + t d to the box [0, size] (slab method).
inline void ClipRayToBox(const Vec3& o, const Vec3& d, const Vec3& size, float& tMin, float& tMax) {
    for (int a = 0; a < 3; ++a) ClipRayToSlab(o, d, size, a, tMin, tMax);
}

// Clips to the volume the renderers see: the box, or with tiling (the volume
// repeating in x and y, SPEC 15) the slab 0 <= z <= size[2] alone.
inline void ClipRayToVolume(const Vec3& o, const Vec3& d, const Vec3& size, bool tiling, float& tMin, float& tMax) {
    for (int a = tiling ? 2 : 0; a < 3; ++a) ClipRayToSlab(o, d, size, a, tMin, tMax);
}

// ---- Tiling (SPEC 15) --------------------------------------------------------------

// x reduced into [0, n] (n x, n y periodic): x - n floor(x / n), with 1 / n
// from the host so that every backend rounds the same product.
inline float TileWrap(float x, float n, float invN) { return x - n * std::floor(x * invN); }

// The voxel that padded index i stands for along an axis of n voxels: voxel
// i - 1 inside; the border (i = 0 and n + 1) is outside (-1), or with `wrap`
// the opposite edge's voxel (n - 1 and 0).
inline int64_t PaddedSourceVoxel(uint32_t i, uint32_t n, bool wrap) {
    if (i >= 1 && i <= n) return int64_t(i) - 1;
    if (!wrap) return -1;
    return i == 0 ? int64_t(n) - 1 : 0;
}

// The camera ray of pixel (x, y) in voxel units, clipped to the box [0, n] (with
// tiling the slab of z in [0, nz]) and to the near and far planes (view depth
// in [near, far], metres).
inline MarchRayGeometry MakePixelRay(const CameraFrame& c, const Vec3& originWorld, float voxelSize, const Vec3& size,
                                     uint32_t x, uint32_t y, bool tiling = false) {
    const PixelDirection p = PixelRayDirection(c, x, y);
    MarchRayGeometry r;
    for (int i = 0; i < 3; ++i) r.origin[i] = (c.eye[i] - originWorld[i]) / voxelSize;
    r.dir = p.dir;
    // depth = t h cosForward.
    const float perDepth = 1.0f / (voxelSize * p.cosForward);
    r.tMin = c.nearPlane * perDepth;
    r.tMax = c.farPlane * perDepth;
    ClipRayToVolume(r.origin, r.dir, size, tiling, r.tMin, r.tMax);
    return r;
}

// ---- Sampling --------------------------------------------------------------------

// Trilinear sample of a canonical volume between voxel centres at voxel-unit
// point p; taps outside the grid read `outside` (q: 0, T: 1), or with `tiling`
// wrap in x and y (the volume repeats with the grid's period). The definition
// the faster samplers (a padded volume on the CPU, textures on GPUs) match.
inline float TrilinearSample(const float* v, const Extent3& e, float outside, const Vec3& p, bool tiling = false) {
    const float px = tiling ? TileWrap(p[0], float(e.nx), 1.0f / float(e.nx)) : p[0];
    const float py = tiling ? TileWrap(p[1], float(e.ny), 1.0f / float(e.ny)) : p[1];
    const float cx = px - 0.5f, cy = py - 0.5f, cz = p[2] - 0.5f;
    const float fx = std::floor(cx), fy = std::floor(cy), fz = std::floor(cz);
    const float wx = cx - fx, wy = cy - fy, wz = cz - fz;
    // Far outside: every tap is outside (also keeps the int conversion defined).
    const float lim = float(std::max({e.nx, e.ny, e.nz})) + 2.0f;
    if (!(std::fabs(fx) < lim && std::fabs(fy) < lim && std::fabs(fz) < lim)) return outside;
    const int64_t i0 = int64_t(fx), j0 = int64_t(fy), k0 = int64_t(fz);
    const int64_t nx = int64_t(e.nx), ny = int64_t(e.ny);
    auto tap = [&](int64_t i, int64_t j, int64_t k) {
        if (tiling) i = (i % nx + nx) % nx, j = (j % ny + ny) % ny;
        if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= int64_t(e.nz)) return outside;
        return v[size_t(i) + size_t(e.nx) * (size_t(j) + size_t(e.ny) * size_t(k))];
    };
    const float c00 = Lerp(tap(i0, j0, k0), tap(i0 + 1, j0, k0), wx);
    const float c10 = Lerp(tap(i0, j0 + 1, k0), tap(i0 + 1, j0 + 1, k0), wx);
    const float c01 = Lerp(tap(i0, j0, k0 + 1), tap(i0 + 1, j0, k0 + 1), wx);
    const float c11 = Lerp(tap(i0, j0 + 1, k0 + 1), tap(i0 + 1, j0 + 1, k0 + 1), wx);
    return Lerp(Lerp(c00, c10, wy), Lerp(c01, c11, wy), wz);
}

// ---- Kernel constants ------------------------------------------------------------

struct MarchSetup {
    Vec3 size{1, 1, 1};   // the box [0, size], voxel units (nx, ny, nz)
    float voxelSize = 1;  // h, metres
    float step = 0.5f;    // Delta_0, voxel edges
    bool adaptive = false;
    float kappa = 0, adaptiveStart = 0;  // Delta(t) = Delta_0 + kappa max(0, t - t_a), t from the eye
    float sigmaH = 1;                    // sigma h: optical depth per voxel edge at q = 1 (finite)
    float epsilon = 0.01f;
    Vec3 sun{0, 0, 1};  // unit, toward the sun
    Vec3 background{0, 0, 0};
    bool powder = false;
    float powderC = 2;
    // The volume repeats in x and y with the grid's period (SPEC 15): rays and light marches are clipped to the
    // slab 0 <= z <= nz alone, samples and bricks read the wrapped point (TileWrap with invSize = 1 / size).
    bool tiling = false;
    Vec3 invSize{1, 1, 1};
    // The light terms (core/math/Light.h; made by core/pipeline/LightTerms.h's MakeLightTerms): the sun's
    // radiance, the ambient light, the phase function, the lightning's point light; light.voxelSize is h.
    LightTerms light;
};

// The point of the volume that voxel-unit point p reads: p itself, or with
// tiling p wrapped into the first period in x and y.
inline Vec3 MarchWrapped(const MarchSetup& s, const Vec3& p) {
    if (!s.tiling) return p;
    return {TileWrap(p[0], s.size[0], s.invSize[0]), TileWrap(p[1], s.size[1], s.invSize[1]), p[2]};
}

// sigma h, capped so that sigma h q l stays free of inf * 0 (as in MakeSliceAttenuation).
inline float MarchOpticalDepthPerVoxel(float sigma, float voxelSize) {
    return sigma > 0 ? std::min(sigma * voxelSize, std::numeric_limits<float>::max()) : 0.0f;
}

// Segment transmittance tau = exp(-sigma h q l), l in voxel edges.
inline float SegmentTransmittance(float sigmaH, float q, float length) {
    return ExpNonPositive(-(sigmaH * q) * length);
}

// Step length at distance t from the eye: fixed, or Olajos's adaptive step.
inline float MarchStepAt(const MarchSetup& s, float t) {
    return s.adaptive ? s.step + s.kappa * std::max(0.0f, t - s.adaptiveStart) : s.step;
}

// Jitter xi of pixel v at `frame` (the step): rand24(seed, frame, 3, v) / 2^24.
inline float MarchJitter(uint32_t seed, uint32_t frame, uint32_t pixel) {
    return float(Rand24(seed, frame, kStreamOther, pixel)) * (1.0f / 16777216.0f);
}

// Powder (Olajos eq. in section 2.5) with d the optical depth toward the sun,
// -ln T_light: 1 - exp(-c d) = 1 - T_light^c.
inline float PowderTerm(float c, float lightT) { return 1.0f - std::pow(std::max(lightT, 0.0f), c); }

// Reinhard tone map of one linear channel with an exposure: x / (1 + x), x = exposure C.
inline float ReinhardToneMap(float c, float exposure) {
    const float x = std::max(c * exposure, 0.0f);
    return std::isinf(x) ? 1.0f : x / (1.0f + x);
}

// ---- Brick skip structure (SPEC 10) ----------------------------------------------

// Bricks of `brick`^3 voxels; empty[b] = 1 iff q_alpha = 0 over the brick grown
// by one voxel, so every trilinear sample inside an empty brick reads q = 0
// exactly. Index bx + bricksX (by + bricksY bz).
struct MarchBricks {
    const uint8_t* empty = nullptr;
    uint32_t brick = 8;
    uint32_t count[3] = {0, 0, 0};
};

// 1/d per component for RayExitFromBox: FLT_MAX where d is (nearly) zero, so
// that axis never bounds the exit (o lies inside that slab of the brick).
inline Vec3 InverseDirection(const Vec3& d) {
    Vec3 inv;
    for (int a = 0; a < 3; ++a) inv[a] = std::fabs(d[a]) < 1e-20f ? std::numeric_limits<float>::max() : 1.0f / d[a];
    return inv;
}

// Distance along o + t d at which the ray leaves the box [lo, hi] (at least t);
// invD = InverseDirection(d).
inline float RayExitFromBox(const Vec3& o, const Vec3& invD, const Vec3& lo, const Vec3& hi, float t) {
    float exit = std::numeric_limits<float>::max();
    for (int a = 0; a < 3; ++a) exit = std::min(exit, ((invD[a] >= 0.0f ? hi[a] : lo[a]) - o[a]) * invD[a]);
    return std::max(exit, t);
}

// The brick that holds voxel-unit point p. With tiling the bricks cover the
// first period and repeat: p's brick is that of its wrapped point, and
// (sx, sy) = n floor(p / n) in x and y carries its box back to p's period.
struct MarchBrickCell {
    bool inside = false;  // p lies in a brick (else the rest is unset)
    uint32_t index = 0;   // bx + count_x (by + count_y bz)
    int b[3] = {0, 0, 0};
    float sx = 0, sy = 0;
};
inline MarchBrickCell MarchBrickAt(const MarchSetup& s, const MarchBricks& b, float invB, const Vec3& p) {
    MarchBrickCell c;
    if (s.tiling) {
        c.sx = s.size[0] * std::floor(p[0] * s.invSize[0]);
        c.sy = s.size[1] * std::floor(p[1] * s.invSize[1]);
    }
    // p * (1/B) may round across a brick face; the bricks' one-voxel margin covers that.
    c.b[0] = int(std::floor((p[0] - c.sx) * invB));
    c.b[1] = int(std::floor((p[1] - c.sy) * invB));
    c.b[2] = int(std::floor(p[2] * invB));
    c.inside = c.b[0] >= 0 && c.b[1] >= 0 && c.b[2] >= 0 && uint32_t(c.b[0]) < b.count[0] &&
               uint32_t(c.b[1]) < b.count[1] && uint32_t(c.b[2]) < b.count[2];
    if (c.inside) c.index = uint32_t(c.b[0]) + b.count[0] * (uint32_t(c.b[1]) + b.count[1] * uint32_t(c.b[2]));
    return c;
}

// The box [lo, hi] of brick c (edge B) at its point's own position along the
// ray; with tiling cut at the period's end in x and y, or a last brick that n
// does not fill would reach into the next period's first.
inline void MarchBrickBox(const MarchSetup& s, const MarchBrickCell& c, float B, Vec3& lo, Vec3& hi) {
    lo = {float(c.b[0]) * B + c.sx, float(c.b[1]) * B + c.sy, float(c.b[2]) * B};
    hi = {lo[0] + B, lo[1] + B, lo[2] + B};
    if (s.tiling) {
        hi[0] = std::min(float(c.b[0]) * B + B, s.size[0]) + c.sx;
        hi[1] = std::min(float(c.b[1]) * B + B, s.size[1]) + c.sy;
    }
}

// The adaptive step's landing after a skip to tExit: the segment starts t_n from t (the skipped sample's segment
// end) on by the recurrence, which is cheap, to the first whose sample t_n + xi l_n lies at or past tExit (or to
// tMax); the positions are those of the unskipped march.
inline float MarchAdaptiveLanding(const MarchSetup& s, float t, float tMax, float xi, float tExit) {
    while (t < tMax) {
        float tAfter = t + MarchStepAt(s, t);
        if (!(tAfter > t)) tAfter = std::nextafter(t, std::numeric_limits<float>::max());
        const float sample = t + xi * (std::min(tAfter, tMax) - t);
        if (sample >= tExit) break;
        t = tAfter;
    }
    return t;
}

// ---- Light functor for the light march (Olajos) -----------------------------------

// What a light functor returns at a sample: transmittance toward the sun, toward
// the point light and toward the sky light (T_sky; 1 where a light is off).
struct MarchLightSample {
    float sun = 1, point = 1, sky = 1;
};

// T along the segment from p toward unit direction u over length `length`
// (voxel edges): n equal segments, midpoint samples of the density functor q.
template <class Density>
float MarchTransmittance(const Vec3& p, const Vec3& u, float length, uint32_t n, float sigmaH, Density&& q) {
    if (!(length > 0.0f) || n == 0) return 1.0f;
    const float dl = length / float(n);
    float depth = 0;
    for (uint32_t j = 0; j < n; ++j) depth += q(MarchAlong(p, u, (float(j) + 0.5f) * dl));
    return ExpNonPositive(-(sigmaH * depth) * dl);
}

// T toward the sun: n_l segments from p to the box exit along s.
template <class Density>
float SunLightMarch(const MarchSetup& s, const Vec3& p, uint32_t n, Density&& q) {
    float t0 = 0, t1 = std::numeric_limits<float>::max();
    ClipRayToVolume(p, s.sun, s.size, s.tiling, t0, t1);
    return t1 > t0 ? MarchTransmittance(p, s.sun, t1, n, s.sigmaH, q) : 1.0f;
}

// T toward the point light: n_l segments from p toward it, ending at the light
// or at the box exit, whichever comes first.
template <class Density>
float PointLightMarch(const MarchSetup& s, const Vec3& p, uint32_t n, Density&& q) {
    const Vec3 toLight{s.light.pointPosition[0] - p[0], s.light.pointPosition[1] - p[1],
                       s.light.pointPosition[2] - p[2]};
    const float dist = std::sqrt(MarchDot(toLight, toLight));
    if (!(dist > 0.0f)) return 1.0f;
    const Vec3 u = MarchScale(toLight, 1.0f / dist);
    float t0 = 0, t1 = dist;
    ClipRayToVolume(p, u, s.size, s.tiling, t0, t1);
    return t1 > t0 ? MarchTransmittance(p, u, t1, n, s.sigmaH, q) : 1.0f;
}

// ---- The per-ray kernel ----------------------------------------------------------

struct MarchRayResult {
    Vec3 color{};                // C = L + T_view background (linear HDR)
    Vec3 light{};                // L alone (a per-pixel background, the ground, composites as L + T_view background)
    float transmittance = 1;     // T_view at the end
    float depthSum = 0;          // sum of T_view (1 - tau) t_sample: the depth's numerator (MarchViewDepth)
    uint32_t samples = 0;        // density samples taken
    uint32_t lightCalls = 0;     // light functor calls (samples with q > 0)
    uint32_t bricksSkipped = 0;  // empty bricks jumped over
};

// Marches one ray (SPEC 10). Segment n is [t_n, t_{n+1}] clipped to tMax,
// t_0 = tMin, t_{n+1} = t_n + Delta(t_n) (fixed: t_n = tMin + n Delta); its
// sample sits at t_n + xi l_n, l_n its clipped length. q(p) returns q_alpha at
// voxel-unit point p (with tiling, at MarchWrapped(p)); light(p) returns a
// MarchLightSample. Samples inside empty
// bricks (bricks may be null) are skipped without moving any other sample.
template <class Density, class Light>
MarchRayResult MarchRay(const MarchSetup& s, const MarchRayGeometry& ray, float xi, const MarchBricks* bricks,
                        Density&& q, Light&& light) {
    MarchRayResult r;
    float L0 = 0, L1 = 0, L2 = 0, T = 1, D = 0;
    if (!ray.Empty()) {
        // cos theta = s . normalize(sample - eye) = s . d on the whole ray (SPEC 8's convention).
        const SunPhases sunPhases = MakeSunPhases(s.light, MarchDot(s.sun, ray.dir));
        const float skyPhase = SkyPhase(s.light, ray.dir);
        const float B = bricks ? float(bricks->brick) : 1.0f, invB = 1.0f / B;
        const Vec3 invDir = InverseDirection(ray.dir);
        float tn = ray.tMin;
        uint32_t n = 0;
        while (tn < ray.tMax) {
            const float delta = MarchStepAt(s, tn);
            float tNext = s.adaptive ? tn + delta : ray.tMin + float(n + 1) * delta;
            // Never stalls: a step below the float spacing at tn still moves on.
            if (!(tNext > tn)) tNext = std::nextafter(tn, std::numeric_limits<float>::max());
            const float len = std::min(tNext, ray.tMax) - tn;
            const float ts = tn + xi * len;
            const Vec3 p = MarchAlong(ray.origin, ray.dir, ts);
            if (bricks) {
                const MarchBrickCell cell = MarchBrickAt(s, *bricks, invB, p);
                if (cell.inside && bricks->empty[cell.index]) {
                    // Jump to the first sample at or past the brick's exit; the samples in between read q = 0.
                    Vec3 lo, hi;
                    MarchBrickBox(s, cell, B, lo, hi);
                    float tExit = RayExitFromBox(ray.origin, invDir, lo, hi, ts);
                    ++r.bricksSkipped;
                    // Walk on through the empty bricks that follow (probing a hundredth of a voxel past each
                    // exit face: the points in between lie within the next brick's one-voxel margin).
                    while (tExit < ray.tMax) {
                        const float tProbe = tExit + 0.01f;
                        const MarchBrickCell next =
                            MarchBrickAt(s, *bricks, invB, MarchAlong(ray.origin, ray.dir, tProbe));
                        if (!next.inside || !bricks->empty[next.index]) break;
                        MarchBrickBox(s, next, B, lo, hi);
                        tExit = RayExitFromBox(ray.origin, invDir, lo, hi, tProbe);
                        ++r.bricksSkipped;
                    }
                    if (s.adaptive) {
                        tn = MarchAdaptiveLanding(s, tNext, ray.tMax, xi, tExit);
                    } else {
                        // First m > n with tMin + (m + xi) Delta >= tExit, rounded down (never past it).
                        const float m = std::floor((tExit - ray.tMin) / delta - xi);
                        n = std::max(n + 1, uint32_t(std::clamp(m, 0.0f, 16777216.0f)));
                        tn = ray.tMin + float(n) * delta;
                    }
                    continue;
                }
            }
            ++r.samples;
            const float qa = q(p);
            if (qa > 0.0f) {
                ++r.lightCalls;
                const float tau = SegmentTransmittance(s.sigmaH, qa, len);
                const MarchLightSample l = light(p);
                float sunGain = SunGain(s.light, sunPhases, l.sun);
                if (s.powder) sunGain *= PowderTerm(s.powderC, l.sun);
                const Vec3 in =
                    InScattered(s.light, LightSample{sunGain, l.sun, l.point, p, ray.dir, l.sky * skyPhase});
                const float w = T * (1.0f - tau);
                L0 += w * in[0];
                L1 += w * in[1];
                L2 += w * in[2];
                D += w * ts;
                T *= tau;
                if (T < s.epsilon || T == 0.0f) break;
            }
            ++n;
            tn = tNext;
        }
    }
    r.transmittance = T;
    r.depthSum = D;
    r.light = {L0, L1, L2};
    r.color = {L0 + T * s.background[0], L1 + T * s.background[1], L2 + T * s.background[2]};
    return r;
}

}  // namespace cb
