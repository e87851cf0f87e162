// The algorithm of the simulation stages (docs/contract.md sections 2-5), in one place.
// Backends keep only their schedule (threading, packing, tiling); the numbers
// they compute come from here (C++) or from the GLSL twins under core/math/.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace cb {

// ---- Region volume (SPEC 2) --------------------------------------------------

// One ellipsoid as every backend rasterises it. Produced on the host from the
// ellipsoid list (core/pipeline/Ellipsoids.h); cos/sin of the yaw are computed once on the
// host so that no backend's own trigonometry enters the result.
struct RasterEllipsoid {
    float center[3];    // voxel units
    float semiAxes[3];  // a, b, c_z in voxels, all > 0
    float cosYaw, sinYaw;
};

// w = max(0, 1 - rho) at a voxel centre p, in float as SPEC 2 writes it.
inline float EllipsoidWeight(const RasterEllipsoid& e, float px, float py, float pz) {
    float ox = px - e.center[0];
    float oy = py - e.center[1];
    float dz = pz - e.center[2];
    // d = Rz(-yaw) (p - c)
    float dx = e.cosYaw * ox + e.sinYaw * oy;
    float dy = -e.sinYaw * ox + e.cosYaw * oy;
    float nx = dx / e.semiAxes[0];
    float ny = dy / e.semiAxes[1];
    float nz = dz / e.semiAxes[2];
    float rho = std::sqrt(nx * nx + ny * ny + nz * nz);
    return std::max(0.0f, 1.0f - rho);
}

// R = min(255, floor(255 * w + 0.5)). Monotone in w, so max-blending the
// quantised values equals quantising the max. Returns 0..255 as int, which
// keeps the caller's loop vectorisable (float -> int, not float -> uint8).
inline int QuantizeRegion(float w) {
    float r = std::floor(255.0f * w + 0.5f);
    return static_cast<int>(std::min(255.0f, r));
}

// ---- Cellular automaton (SPEC 3) -------------------------------------------

// P = (R*Q + 127) / 255 in uint32 (exact; 255*2^24 + 127 < 2^32).
constexpr uint32_t RegionProbability(uint32_t region, uint32_t q) { return (region * q + 127u) / 255u; }

// rand24 < (N / 255 rounded down)  <=>  255*(rand24 + 1) <= N, with N = R*Q + 127.
// The right-hand form needs no division, so vector code can use it; both forms
// are tested against each other (tests/CaRulesTest.cpp).
constexpr bool RegionEventFires(uint32_t rand24, uint32_t region, uint32_t q) {
    return 255u * (rand24 + 1u) <= region * q + 127u;
}

// The 11 growth neighbours (Dobashi eq. 2.4): f(v) = OR of act at v + offset.
// There is no (0,0,+2): activity two slices below spreads upward, not downward.
struct GridOffset {
    int di, dj, dk;
};
inline constexpr std::array<GridOffset, 11> kGrowthNeighbours = {{
    {+1, 0, 0},
    {-1, 0, 0},
    {+2, 0, 0},
    {-2, 0, 0},
    {0, +1, 0},
    {0, -1, 0},
    {0, +2, 0},
    {0, -2, 0},
    {0, 0, +1},
    {0, 0, -1},
    {0, 0, -2},
}};

// ---- Smoothing (SPEC 4) ------------------------------------------------------

// Binomial weights w(d) for |d| <= radius, and the normaliser W = (sum w)^3.
constexpr int SmoothWeight(int radius, int d) {
    constexpr int k1[3] = {1, 2, 1};
    constexpr int k2[5] = {1, 4, 6, 4, 1};
    if (radius == 0) return d == 0 ? 1 : 0;
    if (radius == 1) return (d >= -1 && d <= 1) ? k1[d + 1] : 0;
    return (d >= -2 && d <= 2) ? k2[d + 2] : 0;
}
constexpr uint32_t SmoothNormaliser(int radius) { return radius == 0 ? 1u : radius == 1 ? 64u : 4096u; }

}  // namespace cb
