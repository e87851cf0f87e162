// The exact attenuation reference (SPEC 11) against closed forms and against an
// independent 3-D DDA written here. Distances are in voxel units; the optical
// depth is sigma h times the integral of q along the ray.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "core/math/Random.h"
#include "core/math/Shading.h"
#include "reference/Reference.h"

namespace cb {
namespace {

using ref::OpticalDepthTracer;
using ref::RayStart;
using ref::ReferenceParams;

std::unique_ptr<OpticalDepthTracer> Trace(const Extent3& e, const std::vector<float>& q, int threads = 0) {
    auto tracer = OpticalDepthTracer::Create(e, q, threads);
    EXPECT_TRUE(tracer.has_value()) << (tracer ? "" : tracer.error().message);
    return std::move(*tracer);
}

Vec3 Sun(double elevationDeg, double azimuthDeg) {
    constexpr double kDeg = std::numbers::pi / 180.0;
    return SunDirection(elevationDeg * kDeg, azimuthDeg * kDeg);
}

std::vector<float> Slab(const Extent3& e, uint32_t k0, uint32_t k1, float value) {
    std::vector<float> q(e.Count(), 0.0f);
    for (uint32_t k = k0; k < k1; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) q[VoxelIndex(e, i, j, k)] = value;
    return q;
}

// Test a homogeneous slab (q = c in slices [k0, k1)) at several sun angles: from
// the voxel centre the ray crosses (k1 - (k + 1/2)) / s_z voxels of slab (k1 - k0
// from below it), so T = exp(-sigma h c L / s_z). From the voxel's exit point
// the own voxel's path, 0.5 / max|s_a|, is left out. Ground: G = exp(-sigma h c
// (k1 - k0) / s_z).
TEST(Reference, HomogeneousSlabAtSeveralSunAngles) {
    const Extent3 e{64, 64, 8};
    const uint32_t k0 = 2, k1 = 6;
    const float c = 0.75f;
    auto tracer = Trace(e, Slab(e, k0, k1, c));
    for (double el : {90.0, 70.0, 50.0, 40.0, 30.0})
        for (double az : {0.0, 37.0, 200.0}) {
            ReferenceParams p;
            p.sun = Sun(el, az);
            p.sigma = 0.004;
            p.voxelSize = 50;
            const double sz = p.sun[2];
            const double maxComponent =
                std::max({double(std::fabs(p.sun[0])), double(std::fabs(p.sun[1])), std::fabs(sz)});
            for (RayStart start : {RayStart::VoxelCentre, RayStart::VoxelExit}) {
                p.start = start;
                const std::vector<float> T = tracer->Transmittance(p);
                for (uint32_t k = 0; k < e.nz; ++k) {
                    double path = 0;  // voxels of slab on the ray, counted from the ray's start
                    if (k < k0)
                        path = (k1 - k0) / sz;
                    else if (k < k1)
                        path = (k1 - (k + 0.5)) / sz - (start == RayStart::VoxelExit ? 0.5 / maxComponent : 0.0);
                    const double exact = std::exp(-p.sigma * p.voxelSize * c * path);
                    for (uint32_t j = 24; j < 40; j += 5)
                        for (uint32_t i = 24; i < 40; i += 3)
                            ASSERT_NEAR(T[VoxelIndex(e, i, j, k)], exact, 1e-6)
                                << "el " << el << " az " << az << " " << ref::RayStartName(start) << " k " << k;
                }
            }
            const std::vector<float> G = tracer->GroundShadow(p);
            const double ground = std::exp(-p.sigma * p.voxelSize * c * (k1 - k0) / sz);
            EXPECT_NEAR(G[VoxelIndex(e, 30, 33, 0)], ground, 1e-6) << "el " << el << " az " << az;
        }
}

// Test that the slab test can fail: a sigma 1 % off moves T below the slab by
// more than the tolerance used above.
TEST(Reference, SlabDetectsAWrongSigma) {
    const Extent3 e{32, 32, 8};
    auto tracer = Trace(e, Slab(e, 2, 6, 1.0f));
    ReferenceParams p;
    p.sun = Sun(60, 10);
    p.sigma = 0.004 * 1.01;
    const double exact = std::exp(-0.004 * 50 * 4 / double(p.sun[2]));
    const std::vector<float> T = tracer->Transmittance(p);
    EXPECT_GT(std::fabs(T[VoxelIndex(e, 16, 16, 0)] - exact), 1e-4);
}

// Test G = 1 when the sun is on or below the horizon, whatever the cloud.
TEST(Reference, NoSunNoGroundShadow) {
    const Extent3 e{8, 8, 4};
    auto tracer = Trace(e, Slab(e, 0, 4, 1.0f));
    for (double el : {0.0, -10.0, -90.0}) {
        ReferenceParams p;
        p.sun = Sun(el, 30);
        for (float g : tracer->GroundShadow(p)) ASSERT_EQ(g, 1.0f) << el;
    }
}

// Test a homogeneous box crossed along its diagonal: a ray from outside one
// corner to beyond the opposite one crosses sqrt(a^2 + b^2 + c^2) of it, and
// it passes through voxel edges and corners, where a double count or a miss
// would show. Also the cube filling the grid, sun along (1,1,1)/sqrt 3: from a
// voxel centre the path to the edge is min_a (n - x_a) sqrt 3.
TEST(Reference, BoxAlongItsDiagonal) {
    const Extent3 e{12, 10, 9};
    const uint32_t lo[3] = {2, 3, 1}, size[3] = {7, 5, 6};
    std::vector<float> q(e.Count(), 0.0f);
    const float c = 0.5f;
    for (uint32_t k = lo[2]; k < lo[2] + size[2]; ++k)
        for (uint32_t j = lo[1]; j < lo[1] + size[1]; ++j)
            for (uint32_t i = lo[0]; i < lo[0] + size[0]; ++i) q[VoxelIndex(e, i, j, k)] = c;
    auto tracer = Trace(e, q);
    const double a = size[0], b = size[1], h = size[2];
    const double diagonal = std::sqrt(a * a + b * b + h * h);
    for (int corner = 0; corner < 8; ++corner) {
        // From corner (sx, sy, sz) in {0,1}^3 toward the opposite corner.
        const double from[3] = {lo[0] + ((corner & 1) ? a : 0), lo[1] + ((corner & 2) ? b : 0),
                                lo[2] + ((corner & 4) ? h : 0)};
        const double dir[3] = {(corner & 1) ? -a : a, (corner & 2) ? -b : b, (corner & 4) ? -h : h};
        const Vec3 d{float(dir[0] / diagonal), float(dir[1] / diagonal), float(dir[2] / diagonal)};
        // Start on the corner itself (t > 0 counts); float d is within 1e-7 of the diagonal.
        const double sum = tracer->Integrate({from[0], from[1], from[2]}, d, 0.0);
        EXPECT_NEAR(sum, c * diagonal, 1e-5) << "corner " << corner;
    }

    const Extent3 cube{6, 6, 6};
    auto full = Trace(cube, std::vector<float>(cube.Count(), 1.0f));
    ReferenceParams p;
    const float s = float(1 / std::sqrt(3.0));
    p.sun = {s, s, s};
    p.sigma = 0.01;
    p.voxelSize = 20;
    p.start = RayStart::VoxelCentre;
    const std::vector<float> T = full->Transmittance(p);
    for (uint32_t k = 0; k < 6; ++k)
        for (uint32_t j = 0; j < 6; ++j)
            for (uint32_t i = 0; i < 6; ++i) {
                const double path = std::min({6 - (i + 0.5), 6 - (j + 0.5), 6 - (k + 0.5)}) * std::sqrt(3.0);
                ASSERT_NEAR(T[VoxelIndex(cube, i, j, k)], std::exp(-0.01 * 20 * path), 2e-6) << i << j << k;
            }
}

// Test a sphere of constant density (voxels whose centre is within r of the
// centre hold q = 1). Every such voxel lies inside the ball of radius
// r + sqrt(3)/2, and the ball of radius r - sqrt(3)/2 is covered by them, so a
// ray at distance d from the centre crosses between 2 sqrt((r - sqrt3/2)^2 - d^2)
// and 2 sqrt((r + sqrt3/2)^2 - d^2) of cloud: the chord length, within the
// voxelisation's bound.
TEST(Reference, SphereChordLength) {
    const Extent3 e{40, 40, 40};
    const double centre = 20.0, r = 15.0;
    std::vector<float> q(e.Count(), 0.0f);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                const double x = i + 0.5 - centre, y = j + 0.5 - centre, z = k + 0.5 - centre;
                if (x * x + y * y + z * z <= r * r) q[VoxelIndex(e, i, j, k)] = 1.0f;
            }
    auto tracer = Trace(e, q);
    Pcg32 rng(11);
    const double slack = std::sqrt(3.0) / 2;
    for (int n = 0; n < 200; ++n) {
        // A random direction and a random offset perpendicular to it, |offset| = d < r - slack.
        double dir[3], len;
        do {
            for (double& v : dir) v = rng.NextDouble() * 2 - 1;
            len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
        } while (len < 0.1 || len > 1);
        const Vec3 dv{float(dir[0] / len), float(dir[1] / len), float(dir[2] / len)};
        const double u[3] = {dv[0], dv[1], dv[2]};
        double perp[3] = {rng.NextDouble() - 0.5, rng.NextDouble() - 0.5, rng.NextDouble() - 0.5};
        const double dot = perp[0] * u[0] + perp[1] * u[1] + perp[2] * u[2];
        for (int a = 0; a < 3; ++a) perp[a] -= dot * u[a];
        const double plen = std::sqrt(perp[0] * perp[0] + perp[1] * perp[1] + perp[2] * perp[2]);
        const double d = rng.NextDouble() * (r - slack - 0.5);
        std::array<double, 3> origin;
        for (int a = 0; a < 3; ++a) origin[a] = centre + perp[a] / plen * d - u[a] * 30.0;  // start outside the ball
        const double sum = tracer->Integrate(origin, dv, 0.0);
        const double inner = 2 * std::sqrt((r - slack) * (r - slack) - d * d);
        const double outer = 2 * std::sqrt((r + slack) * (r + slack) - d * d);
        ASSERT_GE(sum, inner - 1e-4) << "ray " << n << " d " << d;
        ASSERT_LE(sum, outer + 1e-4) << "ray " << n << " d " << d;
    }
}

// Test an empty volume: T = 1 and G = 1 exactly, and no geometry at all.
TEST(Reference, EmptyVolumeIsExactlyOne) {
    for (Extent3 e : {Extent3{1, 1, 1}, Extent3{13, 9, 7}}) {
        auto tracer = Trace(e, std::vector<float>(e.Count(), 0.0f));
        EXPECT_EQ(tracer->Primitives(), 0u);
        ReferenceParams p;
        p.sun = Sun(35, 120);
        for (float t : tracer->Transmittance(p)) ASSERT_EQ(t, 1.0f);
        for (float g : tracer->GroundShadow(p)) ASSERT_EQ(g, 1.0f);
    }
}

// Test one voxel: a ray through the centre of a unit cube along unit d crosses
// 1 / max_a |d_a| of it; a ray from the centre crosses half that, which is what
// the voxel-centre start counts and the voxel-exit start leaves out. A ray
// parallel to two axes that grazes a face of the voxel crosses it once or not
// at all, never twice.
TEST(Reference, SingleVoxelPathLength) {
    const Extent3 e{3, 3, 3};
    std::vector<float> q(e.Count(), 0.0f);
    q[VoxelIndex(e, 1, 1, 1)] = 1.0f;
    auto tracer = Trace(e, q);
    Pcg32 rng(4);
    std::vector<Vec3> dirs = {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}, Sun(45, 0), Sun(45, 45), Sun(35.26438968, 45)};
    for (int n = 0; n < 50; ++n) {
        double v[3], len;
        do {
            for (double& x : v) x = rng.NextDouble() * 2 - 1;
            len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        } while (len < 0.1 || len > 1);
        dirs.push_back({float(v[0] / len), float(v[1] / len), float(v[2] / len)});
    }
    for (const Vec3& d : dirs) {
        const double chord =
            1.0 / std::max({std::fabs(double(d[0])), std::fabs(double(d[1])), std::fabs(double(d[2]))});
        // From 4 units behind the centre: 4 is exact in float along any d.
        const std::array<double, 3> behind = {1.5 - 4 * double(d[0]), 1.5 - 4 * double(d[1]), 1.5 - 4 * double(d[2])};
        EXPECT_NEAR(tracer->Integrate(behind, d, 0.0), chord, 1e-5) << d[0] << " " << d[1] << " " << d[2];
        EXPECT_NEAR(tracer->Integrate({1.5, 1.5, 1.5}, d, 0.0), chord / 2, 1e-12);
        EXPECT_NEAR(tracer->Integrate({1.5, 1.5, 1.5}, d, ref::VoxelExitDistance(d)), 0.0, 1e-12);
    }
    // Along +z on the voxel's face x = 1 (and on its edge x = 1, y = 1): one voxel's worth.
    EXPECT_EQ(tracer->Integrate({1.0, 1.5, 0.0}, {0, 0, 1}, 0.0), 1.0);
    EXPECT_EQ(tracer->Integrate({1.0, 1.0, 0.0}, {0, 0, 1}, 0.0), 1.0);
    EXPECT_EQ(tracer->Integrate({2.0, 1.5, 0.0}, {0, 0, 1}, 0.0), 0.0);
}

// Test a ray that runs along the face shared by two occupied voxels of
// different rows (and along their shared edge with a third): it crosses one
// voxel's worth of cloud, not two or none.
TEST(Reference, RayAlongASharedFaceCountsOnce) {
    const Extent3 e{4, 4, 4};
    std::vector<float> q(e.Count(), 0.0f);
    q[VoxelIndex(e, 1, 1, 1)] = 1.0f;
    q[VoxelIndex(e, 1, 2, 1)] = 1.0f;
    q[VoxelIndex(e, 1, 1, 2)] = 1.0f;
    q[VoxelIndex(e, 1, 2, 2)] = 1.0f;
    auto tracer = Trace(e, q);
    EXPECT_EQ(tracer->Integrate({0.0, 2.0, 1.5}, {1, 0, 0}, 0.0), 1.0);  // face y = 2 between rows j = 1, 2
    EXPECT_EQ(tracer->Integrate({0.0, 2.0, 2.0}, {1, 0, 0}, 0.0), 1.0);  // edge shared by four voxels
    EXPECT_EQ(tracer->Integrate({1.5, 2.0, 0.0}, {0, 0, 1}, 0.0), 2.0);  // along z: two slices, once each
}

// An independent Amanatides-Woo traversal: sum of q l from `o` (inside the
// grid or on its boundary, in voxel `start`) along unit d, for t > tStart.
double DdaOpticalDepth(const Extent3& e, const std::vector<float>& q, const double o[3], const int start[3],
                       const double d[3], double tStart) {
    const int n[3] = {int(e.nx), int(e.ny), int(e.nz)};
    int cell[3] = {start[0], start[1], start[2]}, step[3];
    double tMax[3], tDelta[3];
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 0) {
            step[a] = 1;
            tMax[a] = (cell[a] + 1 - o[a]) / d[a];
            tDelta[a] = 1 / d[a];
        } else if (d[a] < 0) {
            step[a] = -1;
            tMax[a] = (cell[a] - o[a]) / d[a];
            tDelta[a] = -1 / d[a];
        } else {
            step[a] = 0;
            tMax[a] = tDelta[a] = INFINITY;
        }
    }
    double t = 0, sum = 0;
    while (cell[0] >= 0 && cell[1] >= 0 && cell[2] >= 0 && cell[0] < n[0] && cell[1] < n[1] && cell[2] < n[2]) {
        const int a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
        const double tNext = tMax[a];
        const double length = tNext - std::max(t, tStart);
        if (length > 0) sum += q[VoxelIndex(e, cell[0], cell[1], cell[2])] * length;
        t = tNext;
        cell[a] += step[a];
        tMax[a] += tDelta[a];
    }
    return sum;
}

// Test T_ref and G_ref against the DDA above on random sparse densities, for
// random suns and the special ones (overhead, along axes, on the 45-degree
// switches, below the horizon), from both ray starts and with 1 and 2 threads:
// optical depths agree within 1e-5 relative.
TEST(Reference, MatchesIndependentDda) {
    const Extent3 e{17, 13, 9};
    Pcg32 rng(21);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    std::vector<Vec3> suns = {{0, 0, 1},    {1, 0, 0},    {0, -1, 0}, Sun(45, 0), Sun(20, 45), Sun(35.26438968, 45),
                              Sun(-30, 70), Sun(1e-4, 10)};
    for (int n = 0; n < 12; ++n) suns.push_back(Sun(rng.NextDouble() * 180 - 90, rng.NextDouble() * 360));
    const double sigma = 0.02, h = 50;
    for (int threads : {1, 2}) {
        auto tracer = Trace(e, q, threads);
        for (const Vec3& s : suns)
            for (RayStart start : {RayStart::VoxelExit, RayStart::VoxelCentre}) {
                ReferenceParams p{s, sigma, h, start};
                const std::vector<float> T = tracer->Transmittance(p);
                const double d[3] = {s[0], s[1], s[2]};
                const double tStart = start == RayStart::VoxelExit ? ref::VoxelExitDistance(s) : 0.0;
                for (uint32_t k = 0; k < e.nz; ++k)
                    for (uint32_t j = 0; j < e.ny; ++j)
                        for (uint32_t i = 0; i < e.nx; ++i) {
                            const double o[3] = {i + 0.5, j + 0.5, k + 0.5};
                            const int cell[3] = {int(i), int(j), int(k)};
                            const double tau = DdaOpticalDepth(e, q, o, cell, d, tStart);
                            const double got = -std::log(double(T[VoxelIndex(e, i, j, k)])) / (sigma * h);
                            ASSERT_NEAR(got, tau, 1e-5 * std::max(1.0, tau) + 2e-7 / (sigma * h))
                                << "sun " << s[0] << "," << s[1] << "," << s[2] << " at " << i << "," << j << "," << k;
                        }
                const std::vector<float> G = tracer->GroundShadow(p);
                for (uint32_t j = 0; j < e.ny; ++j)
                    for (uint32_t i = 0; i < e.nx; ++i) {
                        const double o[3] = {i + 0.5, j + 0.5, 0.0};
                        const int cell[3] = {int(i), int(j), 0};
                        const double tau = s[2] > 0 ? DdaOpticalDepth(e, q, o, cell, d, 0.0) : 0.0;
                        ASSERT_NEAR(G[i + e.nx * j], std::exp(-sigma * h * tau), 1e-6) << i << "," << j;
                    }
            }
    }
}

}  // namespace
}  // namespace cb
