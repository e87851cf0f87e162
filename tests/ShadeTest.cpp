// Light attenuation (SPEC 6) on the CPU backend: exact cases, closed forms,
// the resolution option, every option's bounds and the thread count. The
// sweep's parallel schedule is in tests/ShadeSweepTest.cpp, the ground shadow
// in tests/ShadowTest.cpp, the shared math in tests/ShadingMathTest.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/math/Shading.h"
#include "tests/ShadeTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// Test that an empty volume shades to exactly 1 under every option.
TEST(Shade, EmptyVolumeIsExactlyOne) {
    const Extent3 e{13, 9, 7};
    std::vector<float> q(e.Count(), 0.0f);
    for (AttenuationKind att : {AttenuationKind::Beer, AttenuationKind::Thesis})
        for (int f : {1, 2, 4})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8}) {
                ShadeParams p;
                p.sun = test::Normalized(0.3f, -0.5f, 0.8f);
                p.attenuation = att;
                p.resolution = f;
                p.storage = storage;
                p.scattering = true;
                for (float t : test::ShadeOnCpu(e, q, p)) ASSERT_EQ(t, 1.0f);
            }
}

// Test that with the sun exactly along an axis (no bilinear offset) T is the
// exact product of the per-slice factors above each voxel, for the sun
// overhead (w = z) and along -x (w = x, slices visited from x = 0).
TEST(Shade, AxisAlignedSunIsExactProduct) {
    const Extent3 e{11, 6, 9};
    Pcg32 rng(3);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    ShadeParams p;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    SliceAttenuation a;
    a.opticalDepthPerQ = p.sigma * p.voxelSize;
    // Overhead: T(i,j,k) = prod over k' = nz-1 down to k+1 of A(q(i,j,k')).
    p.sun = {0, 0, 1};
    std::vector<float> T = test::ShadeOnCpu(e, q, p);
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) {
            float t = 1.0f;
            for (int k = int(e.nz) - 1; k >= 0; --k) {
                ASSERT_EQ(T[VoxelIndex(e, i, j, k)], t) << i << "," << j << "," << k;
                t = t * a.Factor(q[VoxelIndex(e, i, j, k)]);
            }
        }
    // Along -x: light enters at x = 0.
    p.sun = {-1, 0, 0};
    T = test::ShadeOnCpu(e, q, p);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j) {
            float t = 1.0f;
            for (uint32_t i = 0; i < e.nx; ++i) {
                ASSERT_EQ(T[VoxelIndex(e, i, j, k)], t) << i << "," << j << "," << k;
                t = t * a.Factor(q[VoxelIndex(e, i, j, k)]);
            }
        }
}

// Test a homogeneous slab (q = 1 in slices [k0, k1)) against the closed form
// T = exp(-sigma (z_top - z) / s_z) at voxel centres, for tilted suns. The
// scheme attenuates whole slices, so a voxel inside the slab sees the slices
// above it but not the half of its own voxel: its optical depth is short by
// tau/2 with tau = sigma h / s_z, and |T - T_exact| <= T_exact (e^(tau/2) - 1).
// Above the slab T is 1; below, the scheme is exact.
TEST(Shade, HomogeneousSlabMatchesClosedForm) {
    const Extent3 e{48, 48, 12};
    const uint32_t k0 = 3, k1 = 9;
    std::vector<float> q(e.Count(), 0.0f);
    for (uint32_t k = k0; k < k1; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) q[VoxelIndex(e, i, j, k)] = 1.0f;
    for (float elevationDeg : {90.0f, 70.0f, 50.0f}) {
        ShadeParams p;
        p.sigma = 0.004f;
        p.voxelSize = 50;
        const float el = elevationDeg * std::numbers::pi_v<float> / 180.0f;
        p.sun = {std::cos(el) * 0.6f, std::cos(el) * 0.8f, std::sin(el)};
        const std::vector<float> T = test::ShadeOnCpu(e, q, p);
        const double tau = double(p.sigma) * p.voxelSize / p.sun[2];
        // Interior columns whose path to the top stays inside the grid.
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 16; j < 32; ++j)
                for (uint32_t i = 16; i < 32; ++i) {
                    double depthVoxels = 0;  // cloud between the voxel centre and the top, in voxels along z
                    if (k < k0)
                        depthVoxels = k1 - k0;
                    else if (k < k1)
                        depthVoxels = k1 - (k + 0.5);
                    const double exact = std::exp(-tau * depthVoxels);
                    const double bound = (k >= k0 && k < k1) ? exact * (std::exp(tau / 2) - 1) : 0.0;
                    ASSERT_NEAR(T[VoxelIndex(e, i, j, k)], exact, bound + 2e-6) << "el " << elevationDeg << " k " << k;
                }
    }
}

// Test the resolution option on a slab. A coarse slice is f voxels thick, so
// the coarse scheme misses up to half a coarse slice of optical depth
// (e^(tau f/2) - 1), and reading T back linearly between coarse centres across
// the slab's top edge adds at most the slope tau times half a coarse cell.
TEST(Shade, CoarseResolutionStaysNearTheClosedForm) {
    const Extent3 e{32, 32, 16};
    std::vector<float> q(e.Count(), 0.0f);
    for (uint32_t k = 4; k < 12; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) q[VoxelIndex(e, i, j, k)] = 1.0f;
    for (int f : {2, 4}) {
        ShadeParams p;
        p.sigma = 0.002f;
        p.voxelSize = 50;
        p.sun = {0, 0, 1};
        p.resolution = f;
        const std::vector<float> T = test::ShadeOnCpu(e, q, p);
        const double tau = double(p.sigma) * p.voxelSize;
        for (uint32_t k = 0; k < e.nz; ++k) {
            double depthVoxels = k < 4 ? 8.0 : k < 12 ? 12 - (k + 0.5) : 0.0;
            const double exact = std::exp(-tau * depthVoxels);
            const double bound = std::exp(tau * f / 2) - 1 + tau * f / 2;
            EXPECT_NEAR(T[VoxelIndex(e, 16, 16, k)], exact, bound) << "f " << f << " k " << k;
        }
    }
}

// Test resolution f against its definition, exactly: on a volume constant in
// every f^3 block (partial blocks at the odd edges included), shading at f
// must equal shading the coarse volume at f = 1 with voxels f times larger,
// read back trilinearly at (i + 0.5)/f - 0.5 (clamped), blended in y and z and
// then in x. This checks the block means and the periodic read-back fast path.
TEST(Shade, ResolutionEqualsCoarseShadeReadTrilinearly) {
    const Extent3 e{37, 29, 11};
    for (int f : {2, 4}) {
        const Extent3 c{CeilDiv(e.nx, f), CeilDiv(e.ny, f), CeilDiv(e.nz, f)};
        Pcg32 rng(17 + f);
        std::vector<float> coarseQ(c.Count());
        for (float& v : coarseQ) v = rng.Below(2) ? float(rng.Below(65)) / 64.0f : 0.0f;
        std::vector<float> q(e.Count());
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 0; j < e.ny; ++j)
                for (uint32_t i = 0; i < e.nx; ++i)
                    q[VoxelIndex(e, i, j, k)] = coarseQ[VoxelIndex(c, i / f, j / f, k / f)];
        ShadeParams p;
        p.sun = test::Normalized(0.3f, 0.6f, 0.7f);
        p.resolution = f;
        const std::vector<float> got = test::ShadeOnCpu(e, q, p);
        ShadeParams coarse = p;
        coarse.resolution = 1;
        coarse.voxelSize = p.voxelSize * float(f);
        const std::vector<float> ct = test::ShadeOnCpu(c, coarseQ, coarse);
        auto tap = [&](uint32_t i, uint32_t cells, uint32_t& i0, uint32_t& i1, float& t) {
            const float x = std::clamp((float(i) + 0.5f) / float(f) - 0.5f, 0.0f, float(cells - 1));
            i0 = uint32_t(x);
            i1 = std::min(i0 + 1, cells - 1);
            t = x - float(i0);
        };
        for (uint32_t k = 0; k < e.nz; ++k)
            for (uint32_t j = 0; j < e.ny; ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    uint32_t x0, x1, y0, y1, z0, z1;
                    float tx, ty, tz;
                    tap(i, c.nx, x0, x1, tx);
                    tap(j, c.ny, y0, y1, ty);
                    tap(k, c.nz, z0, z1, tz);
                    auto at = [&](uint32_t x, uint32_t y, uint32_t z) { return ct[VoxelIndex(c, x, y, z)]; };
                    const float b0 = Bilinear(at(x0, y0, z0), at(x0, y1, z0), at(x0, y0, z1), at(x0, y1, z1), ty, tz);
                    const float b1 = Bilinear(at(x1, y0, z0), at(x1, y1, z0), at(x1, y0, z1), at(x1, y1, z1), ty, tz);
                    const float expected = b0 * (1.0f - tx) + b1 * tx;
                    ASSERT_EQ(got[VoxelIndex(e, i, j, k)], expected)
                        << "f " << f << " at " << i << "," << j << "," << k;
                }
    }
}

// Test every combination of options, with the sun overhead, on and within
// 1e-6 rad of the 45-degree axis switches, near and below the horizon, and
// sigma 0 and 1e6: T is finite and in [0, 1]; sigma = 0 gives exactly 1 (beer).
TEST(Shade, EveryOptionFiniteAndBounded) {
    const Extent3 e{13, 11, 7};
    Pcg32 rng(5);
    std::vector<float> q(e.Count());
    for (float& v : q) v = float(rng.Below(65)) / 64.0f;
    const float d45 = std::numbers::pi_v<float> / 4;
    std::vector<Vec3> suns = {{0, 0, 1},
                              {0, 0, -1},
                              SunDirection(0.0, 0.3),
                              SunDirection(1e-4, 0.2),
                              SunDirection(-0.3, 1.0),
                              SunDirection(0.5, 0.0)};
    for (double eps : {-1e-6, 0.0, 1e-6}) {
        suns.push_back(SunDirection(d45 + eps, 0.0));                            // z/x switch
        suns.push_back(SunDirection(0.3, d45 + eps));                            // y/x switch
        suns.push_back(SunDirection(std::atan(1 / std::sqrt(2.0)) + eps, d45));  // all three equal
    }
    for (const Vec3& sun : suns)
        for (AttenuationKind att : {AttenuationKind::Beer, AttenuationKind::Thesis})
            for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest})
                for (int f : {1, 2, 4})
                    for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8})
                        for (bool scattering : {false, true})
                            for (PhaseKind phase : {PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks})
                                for (float sigma : {0.0f, 0.02f, 1e6f}) {
                                    ShadeParams p;
                                    p.sun = sun;
                                    p.attenuation = att;
                                    p.filter = filter;
                                    p.resolution = f;
                                    p.storage = storage;
                                    p.scattering = scattering;
                                    p.phase = {phase, 0.8f};
                                    p.sigma = sigma;
                                    for (float t : test::ShadeOnCpu(e, q, p, 1)) {
                                        ASSERT_TRUE(std::isfinite(t));
                                        ASSERT_GE(t, 0.0f);
                                        ASSERT_LE(t, 1.0f);
                                        if (sigma == 0 && att == AttenuationKind::Beer) {
                                            ASSERT_EQ(t, 1.0f);
                                        }
                                    }
                                }
}

// Test that sigma = 1e6 blocks all light below any cloud, exactly, without
// subnormal values anywhere.
TEST(Shade, HugeSigmaGivesZero) {
    const Extent3 e{5, 5, 6};
    std::vector<float> q(e.Count(), 0.0f);
    for (uint32_t j = 0; j < 5; ++j)
        for (uint32_t i = 0; i < 5; ++i) q[VoxelIndex(e, i, j, 4)] = 0.5f;
    ShadeParams p;
    p.sun = {0, 0, 1};
    p.sigma = 1e6f;
    const std::vector<float> T = test::ShadeOnCpu(e, q, p);
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t v = 0; v < 25; ++v) {
            const float t = T[v + 25 * k];
            ASSERT_EQ(t, k >= 4 ? 1.0f : 0.0f) << k;
        }
}

// Test that shading does not depend on the thread count.
TEST(Shade, SameForOneAndTwoThreads) {
    const Extent3 e{64, 300, 9};
    Pcg32 rng(9);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(2) ? float(rng.Below(65)) / 64.0f : 0.0f;
    ShadeParams p;
    p.sun = test::Normalized(0.2f, 0.5f, 0.8f);
    EXPECT_EQ(test::ShadeOnCpu(e, q, p, 1), test::ShadeOnCpu(e, q, p, 2));
}

}  // namespace
}  // namespace cb
