// The layered renderer's algorithm (SPEC 15; Wang, Ji and Zhang, sections 4 and 5):
// N horizontal layers around the eye, each fragment the crossing of a pixel's
// ray with one layer plane, composited back to front, and within LOD0's radius
// camera-facing billboards (eq. 13). One per-fragment function for each,
// LayerFragment and BillboardFragment (sharing LayersSampleAt), which the CPU
// and Vulkan run in a per-pixel loop (LayersPixel) and OpenGL's fragment shader
// runs once per rasterised layer or billboard, and its GLSL twin
// core/math/layers.glsl. Decisions where SPEC is silent:
// docs/pipeline.md, "Layered renderer".
//
// Voxel units throughout, as in core/math/March.h: a point p has world
// position origin + h p and t along a ray is in voxel edges.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/math/March.h"

namespace cb {

struct LayersSetup {
    Vec3 eye{};             // the eye, voxel units
    Vec3 size{1, 1, 1};     // the grid (nx, ny, nz)
    Vec3 invSize{1, 1, 1};  // 1 / size: the tiling's wrap
    float voxelSize = 1;    // h, metres
    uint32_t count = 1;     // N layers
    float spacing = 1;      // nz / N, voxel edges between layers
    float outer2 = 0;       // extent^2, voxel edges^2: a fragment's horizontal distance from the eye is within
    float fadeInv2 = 0;     // 1 / (extent^2 - inner^2), voxel edges^-2, inner = (1 - fade) extent; 0: no falloff
    float maxLength = 1;    // l_max, voxel edges: the most path one fragment stands for
    float sigmaH = 1;       // sigma h (MarchOpticalDepthPerVoxel)
    bool tiling = false;    // the volume repeats in x and y; else a fragment outside the box is empty
    // The wind's drift of the volume's coordinates (Wang, Ji and Zhang, eq. 18), voxel units: a fragment at
    // (x, y) reads the volume at (x - drift x, y - drift y). With tiling reduced into [0, n) on the host.
    std::array<float, 2> drift{0, 0};
    // The opacity: beer's, or with `wang` Wang, Ji and Zhang's eq. 16, CoverageModulate(q, m, coverage,
    // density), m the modulation map: nx * ny values at the column centres, x fastest (its own tiling).
    bool wang = false;
    float coverage = 1, density = 1;
    const float* map = nullptr;
    Vec3 sun{0, 0, 1};     // unit, toward the sun
    float lightScale = 1;  // T's factor: 1, or with relighting max(0, s0 . s) (SPEC 15)
    Vec3 background{0, 0, 0};
    // The billboards near the eye (LOD0, SPEC 15; SetLayersLod0): present when inner2 > 0. inner2 is r0^2, the
    // radius of LOD0 squared (voxel edges^2): the layers' annulus starts there, and a billboard's fragment lies
    // within it. A billboard is halfWidth x halfHeight either side of its centre in the camera's image plane, and
    // its fragment stands for billboardLength / cos(ray, forward) of path (beer). docs/pipeline.md, "Layered
    // renderer".
    float inner2 = 0;
    float billboardSpacing = 1;  // p_s, voxel edges: the grid's spacing
    float halfWidth = 0.5f, halfHeight = 0.5f, billboardLength = 1;
    // The light terms (core/math/Light.h; made by MakeLightTerms): the sun and the ambient light; the point
    // light stays off (no transmittance toward it here).
    LightTerms light;
};

// Layer i's plane: z_i = (i + 1/2) nz / N (voxel units, above the grid's base).
inline float LayerHeight(const LayersSetup& s, uint32_t i) { return (float(i) + 0.5f) * s.spacing; }

// The padded (q, T) volume's taps at voxel-unit point p, as core/math/March.h's
// padded sampler (impl_cpu/RenderMarchCpu.cpp): p clamped to [0, n], plus
// 1/2, floored. With tiling the volume's horizontal border holds the opposite
// edge's voxels, so a wrapped point in [0, n] reads across the seam.
struct LayersTaps {
    uint32_t base = 0;  // padded index i + px (j + py k)
    float wx = 0, wy = 0, wz = 0;
};
inline LayersTaps LayersTapsAt(const Vec3& size, const Vec3& p) {
    const float cx = std::clamp(p[0], 0.0f, size[0]) + 0.5f;
    const float cy = std::clamp(p[1], 0.0f, size[1]) + 0.5f;
    const float cz = std::clamp(p[2], 0.0f, size[2]) + 0.5f;
    const uint32_t i = uint32_t(cx), j = uint32_t(cy), k = uint32_t(cz);
    const uint32_t px = uint32_t(size[0]) + 2u, py = uint32_t(size[1]) + 2u;
    return {i + px * (j + py * k), cx - float(i), cy - float(j), cz - float(k)};
}

// Trilinear (q, T), or (q, T, T_sky) with the sky light, from the taps; fetch(paddedIndex) returns the pair
// (the triple), each field blended alone.
template <class Fetch>
inline auto LayersBlend(const Vec3& size, const LayersTaps& t, Fetch&& fetch) {
    const uint32_t px = uint32_t(size[0]) + 2u, pxy = px * (uint32_t(size[1]) + 2u);
    using Fields = std::remove_cvref_t<decltype(fetch(t.base))>;
    Fields out{};
    const Fields a0 = fetch(t.base), a1 = fetch(t.base + 1u), a2 = fetch(t.base + px), a3 = fetch(t.base + px + 1u),
                 b0 = fetch(t.base + pxy), b1 = fetch(t.base + pxy + 1u), b2 = fetch(t.base + pxy + px),
                 b3 = fetch(t.base + pxy + px + 1u);
    for (size_t f = 0; f < out.size(); ++f) {
        const float c00 = Lerp(a0[f], a1[f], t.wx), c10 = Lerp(a2[f], a3[f], t.wx);
        const float c01 = Lerp(b0[f], b1[f], t.wx), c11 = Lerp(b2[f], b3[f], t.wx);
        out[f] = Lerp(Lerp(c00, c10, t.wy), Lerp(c01, c11, t.wy), t.wz);
    }
    return out;
}

// The modulation map at voxel-unit (x, y), x in [0, nx] and y in [0, ny]:
// bilinear between the column centres, the columns wrapping with tiling and
// clamped to the edge ones without.
inline float LayersMapAt(const LayersSetup& s, float x, float y) {
    const int nx = int(s.size[0]), ny = int(s.size[1]);
    const float u = x - 0.5f, v = y - 0.5f;
    const float fu = std::floor(u), fv = std::floor(v);
    const float wu = u - fu, wv = v - fv;
    int i0 = int(fu), i1 = i0 + 1, j0 = int(fv), j1 = j0 + 1;
    if (s.tiling) {
        i0 = i0 < 0 ? i0 + nx : i0, i1 = i1 >= nx ? i1 - nx : i1;
        j0 = j0 < 0 ? j0 + ny : j0, j1 = j1 >= ny ? j1 - ny : j1;
    } else {
        i0 = std::clamp(i0, 0, nx - 1), i1 = std::clamp(i1, 0, nx - 1);
        j0 = std::clamp(j0, 0, ny - 1), j1 = std::clamp(j1, 0, ny - 1);
    }
    const float* m = s.map;
    return Lerp(Lerp(m[i0 + nx * j0], m[i1 + nx * j0], wu), Lerp(m[i0 + nx * j1], m[i1 + nx * j1], wu), wv);
}

// The opacity's falloff toward the extent at squared horizontal distance r2:
// w^2 (3 - 2 w), w = clamp((outer2 - r2) fadeInv2, 0, 1): 1 within the inner
// radius, 0 at the extent and beyond, smooth between (w linear in r^2).
// fadeInv2 0: 1 everywhere (a hard cut at the extent).
inline float LayersFade(float r2, float outer2, float fadeInv2) {
    if (!(fadeInv2 > 0.0f)) return 1.0f;
    const float w = std::min(std::max((outer2 - r2) * fadeInv2, 0.0f), 1.0f);
    return (w * w) * (3.0f - 2.0f * w);
}

// One pixel's ray as the layers see it: its direction (PixelRayDirection) and
// the distances of the near and far planes along it (voxel edges).
struct LayersRay {
    Vec3 dir{};
    float tNear = 0, tFar = 0;
    float cosForward = 1;  // dir . forward: a point at view depth D lies at t = D / cosForward
};
inline LayersRay MakeLayersRay(const CameraFrame& c, float voxelSize, uint32_t x, uint32_t y) {
    const PixelDirection p = PixelRayDirection(c, x, y);
    const float perDepth = 1.0f / (voxelSize * p.cosForward);
    return {p.dir, c.nearPlane * perDepth, c.farPlane * perDepth, p.cosForward};
}

// The fragment result of a layer or a billboard.
struct LayerFragmentResult {
    bool crossed = false;  // the plane is met in range (a counted fragment)
    bool drawn = false;    // and q > 0 there
    float alpha = 0;
    Vec3 color{};
};

// A fragment's sample, shared by a layer's and a billboard's: the point (eye x + hx, eye y + hy, z) (voxel units)
// at squared horizontal distance r2 from the eye, standing for `length` of path. Moved by the drift and wrapped
// (tiling), or outside the box [0, nx] x [0, ny] not a fragment; drawn where q > 0. Its opacity is beer's,
// alpha = 1 - exp(-sigma h q length), or wang's (eq. 16 of q and the map, without a path length), times
// LayersFade(r2); its colour c = sun SunGain(T lightScale) + ambient (with the ray's sunPhases: T lightScale P^(s . d)
// with one octave), plus the sky light's T_sky P^(s_sky . d) where fetch returns T_sky as a third field.
// Always inlined: with two callers GCC keeps it out of line, and the call costs the CPU's layers a quarter of
// their time on wang-20km (reports/perf/lod0-layers-cost.md).
template <class Fetch>
[[gnu::always_inline]] inline LayerFragmentResult LayersSampleAt(const LayersSetup& s, const LayersRay& ray,
                                                                 const SunPhases& sunPhases, float hx, float hy,
                                                                 float z, float r2, float length, Fetch&& fetch) {
    LayerFragmentResult f;
    float x = (s.eye[0] + hx) - s.drift[0], y = (s.eye[1] + hy) - s.drift[1];
    if (s.tiling) {
        x = TileWrap(x, s.size[0], s.invSize[0]);
        y = TileWrap(y, s.size[1], s.invSize[1]);
    } else if (!(x >= 0.0f && x <= s.size[0] && y >= 0.0f && y <= s.size[1])) {
        return f;
    }
    f.crossed = true;
    const LayersTaps taps = LayersTapsAt(s.size, Vec3{x, y, z});
    // A fetch that knows where all eight taps read q = 0 (the CPU's, impl_cpu/LayersOccupancyCpu-inl.h) skips the blend
    // there: the blended q would be 0 exactly, and the fragment is crossed but not drawn, as below.
    if constexpr (requires { fetch.TapsEmpty(taps.base); })
        if (fetch.TapsEmpty(taps.base)) return f;
    const auto qt = LayersBlend(s.size, taps, fetch);
    if (!(qt[0] > 0.0f)) return f;
    f.drawn = true;
    if (s.wang) {
        f.alpha = CoverageModulate(qt[0], LayersMapAt(s, x, y), s.coverage, s.density);
    } else {
        f.alpha = 1.0f - SegmentTransmittance(s.sigmaH, qt[0], length);
    }
    f.alpha = f.alpha * LayersFade(r2, s.outer2, s.fadeInv2);
    const float lit = qt[1] * s.lightScale;  // T, or relit
    const float gain = SunGain(s.light, sunPhases, lit);
    // The sample (voxel units, before the drift and the wrap).
    const Vec3 at{s.eye[0] + hx, s.eye[1] + hy, z};
    float skyGain = 0.0f;
    if constexpr (qt.size() > 2)
        if (s.light.skyOn) skyGain = qt[2] * SkyPhase(s.light, ray.dir);
    f.color = InScattered(s.light, LightSample{gain, lit, 1.0f, at, ray.dir, skyGain});
    return f;
}

// Layer i's fragment on a ray: drawn iff the ray crosses the plane at a
// distance t between the near and far planes, within the annulus horizontally
// (r0 <= r <= extent) and (without tiling) inside the box, where q > 0
// (LayersSampleAt, with l = min(spacing / |d_z|, l_max)).
template <class Fetch>
inline LayerFragmentResult LayerFragment(const LayersSetup& s, const LayersRay& ray, const SunPhases& sunPhases,
                                         uint32_t i, Fetch&& fetch) {
    LayerFragmentResult f;
    const float dz = ray.dir[2];
    if (!(std::fabs(dz) >= 1e-20f)) return f;
    const float z = LayerHeight(s, i);
    const float invDz = 1.0f / dz;
    const float t = (z - s.eye[2]) * invDz;
    if (!(t >= ray.tNear && t <= ray.tFar && t > 0.0f)) return f;
    const float hx = ray.dir[0] * t, hy = ray.dir[1] * t;
    const float r2 = hx * hx + hy * hy;
    if (!(r2 <= s.outer2 && r2 >= s.inner2)) return f;
    const float length = std::min(s.spacing * std::fabs(invDz), s.maxLength);
    return LayersSampleAt(s, ray, sunPhases, hx, hy, z, r2, length, fetch);
}

// ---- Billboards (LOD0) ----

// One billboard: its centre (voxel units, on a layer's plane) and its view depth (centre - eye) . forward, > 0.
struct LayersBillboard {
    Vec3 centre{};
    float depth = 0;
};

// A call's billboards in drawing order, with the camera's right and up (the billboards' plane).
struct LayersBillboards {
    const LayersBillboard* items = nullptr;
    uint32_t count = 0;
    Vec3 right{1, 0, 0}, up{0, 0, 1};
};

// LOD0's constants from its radius r0 and the grid's spacing p_s (both voxel edges; r0 0: no billboards), with
// Wang, Ji and Zhang's eq. 13 as docs/pipeline.md reads it: W_p = p_s, H_p = max(dz, p_s) with dz the layers'
// spacing (eq. 12's Thickness / (N - 1)), and a fragment's path min(p_s, dz) / cos(ray, forward).
inline void SetLayersLod0(LayersSetup& s, double radius, double spacing) {
    s.inner2 = float(radius * radius);
    s.billboardSpacing = float(spacing);
    s.halfWidth = float(0.5 * spacing);
    s.halfHeight = float(0.5 * std::max(double(s.spacing), spacing));
    s.billboardLength = float(std::min(double(s.spacing), spacing));
}

// A billboard's fragment on a ray: the ray meets the billboard's plane (perpendicular to forward, through its
// centre) at t = depth / cosForward, drawn iff t lies between the near and far planes, the point lies within
// halfWidth along right and halfHeight along up of the centre, strictly within r0 of the eye horizontally
// (r^2 < inner2) and within the grid's height [0, nz]; then as a layer's (LayersSampleAt, with
// l = min(billboardLength / cosForward, l_max)).
template <class Fetch>
inline LayerFragmentResult BillboardFragment(const LayersSetup& s, const LayersBillboards& b, const LayersRay& ray,
                                             const SunPhases& sunPhases, const LayersBillboard& bb, Fetch&& fetch) {
    LayerFragmentResult f;
    const float t = bb.depth / ray.cosForward;
    if (!(t >= ray.tNear && t <= ray.tFar && t > 0.0f)) return f;
    const float hx = ray.dir[0] * t, hy = ray.dir[1] * t, hz = ray.dir[2] * t;
    const float r2 = hx * hx + hy * hy;
    if (!(r2 < s.inner2 && r2 <= s.outer2)) return f;
    const float ox = (s.eye[0] + hx) - bb.centre[0], oy = (s.eye[1] + hy) - bb.centre[1];
    const float z = s.eye[2] + hz;
    const float oz = z - bb.centre[2];
    const float u = ox * b.right[0] + oy * b.right[1] + oz * b.right[2];
    const float v = ox * b.up[0] + oy * b.up[1] + oz * b.up[2];
    if (!(std::fabs(u) <= s.halfWidth && std::fabs(v) <= s.halfHeight)) return f;
    if (!(z >= 0.0f && z <= s.size[2])) return f;
    const float length = std::min(s.billboardLength / ray.cosForward, s.maxLength);
    return LayersSampleAt(s, ray, sunPhases, hx, hy, z, r2, length, fetch);
}

// The pixels a billboard's fragments can cover, conservatively: its quad projected (a rectangle, the quad being
// parallel to the image plane) in pixel coordinates, x from the left and y (rows) from the top, [x0, x1] x [y0, y1],
// grown by two pixels and by 1e-5 of the coordinates' magnitude (voxel edges) for the float rounding of
// BillboardFragment's test; worked in double. OpenGL's vertex shader draws the same rectangle; the CPU culls a
// tile's billboards with it.
struct LayersPixelRect {
    double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};
inline LayersPixelRect LayersBillboardRect(const LayersSetup& s, const CameraFrame& c, const LayersBillboard& b) {
    const double depth = b.depth, focal = c.focalPx;
    double x = 0, y = 0, scale = 1;
    for (int a = 0; a < 3; ++a) {
        const double rel = double(b.centre[a]) - double(s.eye[a]);
        x += rel * c.right[a];
        y += rel * c.upVector[a];
        scale = std::max({scale, std::fabs(double(b.centre[a])), std::fabs(double(s.eye[a]))});
    }
    const double margin = 2.0 * depth / focal + 1e-5 * scale;
    const double hw = s.halfWidth + margin, hh = s.halfHeight + margin;
    return {0.5 * c.width + focal * (x - hw) / depth, 0.5 * c.width + focal * (x + hw) / depth,
            0.5 * c.height - focal * (y + hh) / depth, 0.5 * c.height - focal * (y - hh) / depth};
}

// The grid points of LOD0 (SPEC 15): on every layer's plane, the centres ((a + 1/2) p_s, (b + 1/2) p_s, z_i)
// (voxel units: the cells of side p_s from the grid's origin, a billboard at each cell's centre) whose horizontal
// distance from the eye is at most r0 (worked in double), in front of the eye (depth > 0: one behind it has no
// fragment); back to front: decreasing depth (the eye's distance to the billboard's plane, as the layers'
// |z_i - z_eye|), ties in the order layer, b, a. Empty when r0 is 0.
inline std::vector<LayersBillboard> MakeLayersBillboards(const LayersSetup& s, const Vec3& forward) {
    std::vector<LayersBillboard> out;
    if (!(s.inner2 > 0.0f)) return out;
    const double ps = s.billboardSpacing, r0 = std::sqrt(double(s.inner2));
    const double ex = s.eye[0], ey = s.eye[1];
    const double fa0 = std::floor((ex - r0) / ps - 0.5), fa1 = std::ceil((ex + r0) / ps - 0.5);
    const double fb0 = std::floor((ey - r0) / ps - 0.5), fb1 = std::ceil((ey + r0) / ps - 0.5);
    // Beyond 2^52 cells of the grid's origin (or not finite) no float tells the cells apart: no billboards.
    constexpr double kMostCells = 4503599627370496.0;
    for (double f : {fa0, fa1, fb0, fb1})
        if (!(std::fabs(f) <= kMostCells)) return out;
    const int64_t a0 = int64_t(fa0), a1 = int64_t(fa1), b0 = int64_t(fb0), b1 = int64_t(fb1);
    for (uint32_t i = 0; i < s.count; ++i) {
        const float z = LayerHeight(s, i);
        for (int64_t b = b0; b <= b1; ++b)
            for (int64_t a = a0; a <= a1; ++a) {
                const float cx = float((double(a) + 0.5) * ps), cy = float((double(b) + 0.5) * ps);
                const double dx = double(cx) - ex, dy = double(cy) - ey;
                if (!(dx * dx + dy * dy <= double(s.inner2))) continue;
                const float depth =
                    (cx - s.eye[0]) * forward[0] + (cy - s.eye[1]) * forward[1] + (z - s.eye[2]) * forward[2];
                if (!(depth > 0.0f)) continue;
                out.push_back({{cx, cy, z}, depth});
            }
    }
    std::stable_sort(out.begin(), out.end(),
                     [](const LayersBillboard& x, const LayersBillboard& y) { return x.depth > y.depth; });
    return out;
}

// C <- alpha c + (1 - alpha) C, per channel: the blend every backend uses
// (OpenGL's SRC_ALPHA, ONE_MINUS_SRC_ALPHA).
inline Vec3 LayersOver(const Vec3& C, float alpha, const Vec3& c) {
    const float keep = 1.0f - alpha;
    return {alpha * c[0] + keep * C[0], alpha * c[1] + keep * C[1], alpha * c[2] + keep * C[2]};
}

// The layers one ray crosses, back to front: those on its side of the eye,
// the farthest first (SPEC 15's order: decreasing |z_i - z_eye|). first is
// the farthest, and the walk moves by step (-1 upward, +1 downward) for count
// layers; count 0 when the ray is level or no layer lies on its side.
struct LayersWalk {
    int first = 0, step = 0;
    uint32_t count = 0;
};
inline LayersWalk LayersWalkOf(const LayersSetup& s, float dz) {
    LayersWalk w;
    if (dz > 0.0f) {
        // Layers above the eye: i from N - 1 down to the lowest with z_i > eye z.
        uint32_t lowest = s.count;
        while (lowest > 0 && LayerHeight(s, lowest - 1) > s.eye[2]) --lowest;
        w = {int(s.count) - 1, -1, s.count - lowest};
    } else if (dz < 0.0f) {
        uint32_t above = 0;  // layers below the eye: i from 0 up to the highest with z_i < eye z
        while (above < s.count && LayerHeight(s, above) < s.eye[2]) ++above;
        w = {0, 1, above};
    }
    return w;
}

// The walks of one call: LayersWalkOf depends on the ray only through the sign
// of d_z, so a call makes both once (rays up, rays down) rather than per pixel.
struct LayersWalks {
    LayersWalk up, down;
};
inline LayersWalks MakeLayersWalks(const LayersSetup& s) { return {LayersWalkOf(s, 1.0f), LayersWalkOf(s, -1.0f)}; }

struct LayersPixelResult {
    Vec3 color{};
    uint32_t fragments = 0;  // crossings in range
    uint32_t drawn = 0;      // of them with q > 0
};

// The sun's phase values on a ray, P^(s . d) of each octave (MakeSunPhases): one per pixel, shared by its fragments.
inline SunPhases LayersSunPhases(const LayersSetup& s, const LayersRay& ray) {
    return MakeSunPhases(s.light, MarchDot(s.sun, ray.dir));
}

// A fragment into a pixel's result: counted when crossed, blended over it when drawn.
inline void LayersAccumulate(LayersPixelResult& r, const LayerFragmentResult& f) {
    r.fragments += f.crossed ? 1u : 0u;
    if (!f.drawn) return;
    ++r.drawn;
    r.color = LayersOver(r.color, f.alpha, f.color);
}

// The billboards' fragments of one pixel in their order, over what its layers left in r.
template <class Fetch>
inline void LayersBillboardsOver(const LayersSetup& s, const LayersBillboards& billboards, const LayersRay& ray,
                                 const SunPhases& sunPhases, Fetch&& fetch, LayersPixelResult& r) {
    for (uint32_t n = 0; n < billboards.count; ++n)
        LayersAccumulate(r, BillboardFragment(s, billboards, ray, sunPhases, billboards.items[n], fetch));
}

// The layer walk of a ray: walks.up or walks.down by the sign of d_z; none for a level ray, and none where
// |d_z| < 1e-20, where LayerFragment crosses no plane.
inline LayersWalk LayersWalkOfRay(const LayersWalks& walks, const LayersRay& ray) {
    const float dz = ray.dir[2];
    if (!(std::fabs(dz) >= 1e-20f)) return {};
    return dz > 0.0f ? walks.up : walks.down;
}

// One pixel: the background, then every layer the ray crosses, back to front
// (walks: MakeLayersWalks(s)), then the billboards in their order: every billboard fragment lies within r0 of the
// eye horizontally and every layer fragment at r0 or beyond, so on one ray all the billboards' are nearer.
template <class Fetch>
inline LayersPixelResult LayersPixel(const LayersSetup& s, const LayersWalks& walks, const LayersRay& ray,
                                     Fetch&& fetch, const LayersBillboards& billboards = {}) {
    LayersPixelResult r;
    r.color = s.background;
    const SunPhases sunPhases = LayersSunPhases(s, ray);
    const LayersWalk w = LayersWalkOfRay(walks, ray);
    for (uint32_t n = 0; n < w.count; ++n)
        LayersAccumulate(r, LayerFragment(s, ray, sunPhases, uint32_t(w.first + w.step * int(n)), fetch));
    LayersBillboardsOver(s, billboards, ray, sunPhases, fetch, r);
    return r;
}

}  // namespace cb
