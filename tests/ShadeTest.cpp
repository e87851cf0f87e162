// Light attenuation (SPEC 6), the ground shadow (SPEC 7) and their shared math.
#include <gtest/gtest.h>
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/Random.h"
#include "core/ShadePlan.h"
#include "core/Shading.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/ShadeSchedule.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// T starts as `initialT` everywhere (NaN: a cell read before it is written shows).
std::vector<float> ShadeOnCpu(const Extent3& e, const std::vector<float>& q, const ShadeParams& p, int threads = 0,
                              float initialT = 0.0f) {
    cpu::BackendCpu backend(threads);
    auto qb = test::MakeFilled(backend, BufferFormat::F32, e, q);
    auto T = test::MakeFilled(backend, BufferFormat::F32, e, std::vector<float>(e.Count(), initialT));
    Status s = backend.Shade(p, *qb, *T);
    EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
    return test::Read<float>(backend, *T);
}

Vec3 Normalized(float x, float y, float z) {
    const float l = std::sqrt(x * x + y * y + z * z);
    return {x / l, y / l, z / l};
}

// Test the accurate vectorisable exp against std::exp in double: within 2 ulp
// on [-87, 0], exactly 0 below.
TEST(ShadingMath, ExpWithinTwoUlp) {
    for (int n = 0; n <= 870000; ++n) {
        const float x = -float(n) * 1e-4f;
        const float got = ExpNonPositive(x);
        const double want = std::exp(double(x));
        const double ulp = std::nextafter(float(want), 1.0f) - float(want);
        ASSERT_LE(std::fabs(got - want), 2 * ulp) << "x = " << x;
    }
    EXPECT_EQ(ExpNonPositive(0.0f), 1.0f);
    EXPECT_EQ(ExpNonPositive(-88.0f), 0.0f);
    EXPECT_EQ(ExpNonPositive(-1e30f), 0.0f);
}

// Test the software float -> half rounding against the CPU's F16C conversion
// (round to nearest even) on every float in [0, 1] with a step of 2^-20 and
// on every value near half's subnormal boundary.
TEST(ShadingMath, RoundToHalfMatchesF16C) {
    if (!__builtin_cpu_supports("f16c")) GTEST_SKIP() << "unsupported here: no F16C";
    auto hardware = [](float v) { return _cvtsh_ss(_cvtss_sh(v, _MM_FROUND_TO_NEAREST_INT)); };
    for (uint32_t n = 0; n <= (1u << 20); ++n) {
        const float v = float(n) / float(1u << 20);
        ASSERT_EQ(RoundToHalf(v), hardware(v)) << v;
    }
    for (uint32_t bits = 0x38000000u; bits < 0x38900000u; bits += 7) {
        const float v = std::bit_cast<float>(bits);
        ASSERT_EQ(RoundToHalf(v), hardware(v)) << v;
    }
}

// Test unorm8 rounding: multiples of 1/255, nearest.
TEST(ShadingMath, RoundToUnorm8) {
    EXPECT_EQ(RoundToUnorm8(0.0f), 0.0f);
    EXPECT_EQ(RoundToUnorm8(1.0f), 1.0f);
    EXPECT_EQ(RoundToUnorm8(0.5f), 128.0f / 255.0f);  // 127.5 -> 128 (ties to even)
    EXPECT_EQ(RoundToUnorm8(0.1f), 26.0f / 255.0f);   // 25.5 -> 26 (25.5000004 in float)
}

// Test the stored codes against an independent decoding: every half code in
// [0, 1] (0 .. 0x3C00), built with ldexp from its exponent and mantissa fields,
// gives its own code back, and so does every k/255; hand values besides.
TEST(ShadingMath, StorageCodesAreTheStoredIntegers) {
    for (uint32_t code = 0; code <= 0x3C00u; ++code) {
        const uint32_t exponent = code >> 10, mantissa = code & 0x3ffu;
        const float value = exponent == 0 ? float(std::ldexp(double(mantissa), -24))
                                          : float(std::ldexp(1.0 + mantissa / 1024.0, int(exponent) - 15));
        ASSERT_EQ(StorageCode(StorageFormat::Fp16, value), code) << value;
    }
    EXPECT_EQ(StorageCode(StorageFormat::Fp16, 1.0f), 0x3C00u);
    EXPECT_EQ(StorageCode(StorageFormat::Fp16, 0.5f), 0x3800u);
    EXPECT_EQ(StorageCode(StorageFormat::Fp16, 0x1p-24f), 1u);      // the smallest subnormal half
    EXPECT_EQ(StorageCode(StorageFormat::Fp16, 0x1p-14f), 0x400u);  // the smallest normal half
    for (uint32_t k = 0; k <= 255; ++k) ASSERT_EQ(StorageCode(StorageFormat::Unorm8, float(k) / 255.0f), k);
    // Issue 16's case (on the H200 it was 214/255 against 215/255 as the GPU rounded them): neighbouring codes
    // whose float difference exceeds 1/255 in single precision, here 127/255 and 128/255 (also 3, 7, 15, 31, 63).
    const float a = 127.0f / 255.0f, b = 128.0f / 255.0f;
    EXPECT_GT(b - a, 1.0f / 255.0f);
    EXPECT_EQ(StorageCode(StorageFormat::Unorm8, b) - StorageCode(StorageFormat::Unorm8, a), 1u);
}

// Test the principal axis rule, including exact ties (z wins over y, y over x).
TEST(ShadingMath, PrincipalAxisTies) {
    EXPECT_EQ(PrincipalAxis({0, 0, 1}), 2);
    EXPECT_EQ(PrincipalAxis({1, 0, 1}), 2);     // |s_z| = |s_x|: z
    EXPECT_EQ(PrincipalAxis({1, 1, 0.5f}), 1);  // |s_y| = |s_x|: y
    EXPECT_EQ(PrincipalAxis({-1, 0.5f, 0.5f}), 0);
    EXPECT_EQ(PrincipalAxis({0.3f, -0.9f, 0.2f}), 1);
}

// Test the phase functions: isotropic HG (g = 0) is 1, HG forward peak
// (1+g)/(1-g)^2, Cornette-Shanks at g = 0 is 3/4 (1 + cos^2).
TEST(ShadingMath, PhaseFunctionsHandWorked) {
    EXPECT_FLOAT_EQ(PhaseValue({PhaseKind::HenyeyGreenstein, 0.0f}, 0.3f), 1.0f);
    EXPECT_FLOAT_EQ(PhaseValue({PhaseKind::HenyeyGreenstein, 0.5f}, 1.0f), 1.5f / 0.25f);
    EXPECT_FLOAT_EQ(PhaseValue({PhaseKind::CornetteShanks, 0.0f}, 1.0f), 1.5f);
    EXPECT_FLOAT_EQ(PhaseValue({PhaseKind::CornetteShanks, 0.0f}, 0.0f), 0.75f);
    EXPECT_EQ(PhaseValue({PhaseKind::None, 0.9f}, -1.0f), 1.0f);
    // Normalisation: the mean of P^ over the sphere is 1 (midpoint rule in cos theta).
    for (PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks}) {
        double sum = 0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) sum += PhaseValue({kind, 0.6f}, -1.0f + 2.0f * (float(i) + 0.5f) / float(n));
        EXPECT_NEAR(sum / n, 1.0, 2e-3) << int(kind);
    }
}

// Test that an empty volume shades to exactly 1 under every option.
TEST(Shade, EmptyVolumeIsExactlyOne) {
    const Extent3 e{13, 9, 7};
    std::vector<float> q(e.Count(), 0.0f);
    for (AttenuationKind att : {AttenuationKind::Beer, AttenuationKind::Thesis})
        for (int f : {1, 2, 4})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8}) {
                ShadeParams p;
                p.sun = Normalized(0.3f, -0.5f, 0.8f);
                p.attenuation = att;
                p.resolution = f;
                p.storage = storage;
                p.scattering = true;
                for (float t : ShadeOnCpu(e, q, p)) ASSERT_EQ(t, 1.0f);
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
    std::vector<float> T = ShadeOnCpu(e, q, p);
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
    T = ShadeOnCpu(e, q, p);
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
        const std::vector<float> T = ShadeOnCpu(e, q, p);
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
        const std::vector<float> T = ShadeOnCpu(e, q, p);
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
        p.sun = Normalized(0.3f, 0.6f, 0.7f);
        p.resolution = f;
        const std::vector<float> got = ShadeOnCpu(e, q, p);
        ShadeParams coarse = p;
        coarse.resolution = 1;
        coarse.voxelSize = p.voxelSize * float(f);
        const std::vector<float> ct = ShadeOnCpu(c, coarseQ, coarse);
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
                                    for (float t : ShadeOnCpu(e, q, p, 1)) {
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
    const std::vector<float> T = ShadeOnCpu(e, q, p);
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
    p.sun = Normalized(0.2f, 0.5f, 0.8f);
    EXPECT_EQ(ShadeOnCpu(e, q, p, 1), ShadeOnCpu(e, q, p, 2));
}

// The sweep of SPEC 6 written plainly, one voxel at a time in slice order:
// T = 1 on the first slice; after it, T = store(bilinear T, factor(bilinear q))
// of the previous slice at (u + u0, v + v0), with T = 1 and q = 0 outside.
std::vector<float> PlainShadeSweep(const Extent3& e, const std::vector<float>& q, const ShadeParams& p) {
    const ShadePlan plan = MakeShadePlan(p, e);
    const ShearWarp& g = plan.geometry;
    std::vector<float> T(e.Count(), -1.0f);
    auto index = [&](int64_t a, int64_t b, uint32_t w) {
        uint32_t c[3];
        c[g.u] = uint32_t(a);
        c[g.v] = uint32_t(b);
        c[g.w] = w;
        return VoxelIndex(e, c[0], c[1], c[2]);
    };
    auto inside = [&](int64_t a, int64_t b) { return a >= 0 && b >= 0 && a < plan.nu && b < plan.nv; };
    for (uint32_t m = 0; m < plan.nw; ++m)
        for (int64_t b = 0; b < plan.nv; ++b)
            for (int64_t a = 0; a < plan.nu; ++a) {
                if (m == 0) {
                    T[index(a, b, plan.SliceW(0))] = 1.0f;
                    continue;
                }
                const uint32_t w = plan.SliceW(m - 1);
                auto t = [&](int64_t x, int64_t y) { return inside(x, y) ? T[index(x, y, w)] : 1.0f; };
                auto d = [&](int64_t x, int64_t y) { return inside(x, y) ? q[index(x, y, w)] : 0.0f; };
                const int64_t x = a + g.u0, y = b + g.v0;
                const float tt = Bilinear(t(x, y), t(x + 1, y), t(x, y + 1), t(x + 1, y + 1), g.fu, g.fv);
                const float qq = Bilinear(d(x, y), d(x + 1, y), d(x, y + 1), d(x + 1, y + 1), g.fu, g.fv);
                T[index(a, b, plan.SliceW(m))] = StoreTransmittance(p.storage, tt, plan.attenuation.Factor(qq));
            }
    return T;
}

// Test that the CPU's shade on 2, 5 and 16 threads (the slice plane in bands
// along v on 2 and 5, along u on 16, run as a pipeline of tiles) equals a
// plain per-voxel sweep written separately, bit for bit, on odd sizes: each
// principal axis, both sun signs, the 45 degree ties, both filters and every
// storage; and that the coarse resolutions do not depend on the thread count
// either. T starts as NaN, so a tile that read a cell of another band before
// that band wrote it would show here even on one core (the tiles' order
// comes from their dependencies, not from the cores).
TEST(Shade, ParallelSweepEqualsPlainSweep) {
    const Extent3 e{67, 53, 41};
    Pcg32 rng(16);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) ? float(rng.Below(65)) / 64.0f : 0.0f;
    const float d45 = std::numbers::pi_v<float> / 4;
    const std::vector<Vec3> suns = {SunDirection(0.3, 0.2),      SunDirection(0.3, 3.3),  // x, both signs
                                    SunDirection(0.4, 1.4),      SunDirection(0.4, -1.7),  // y
                                    SunDirection(1.1, 0.5),      SunDirection(-1.2, 2.0),  // z
                                    SunDirection(d45, 0.0),      SunDirection(0.3, d45),
                                    Normalized(-0.3f, 0.9f, 0.4f)};
    int compared = 0;
    for (const Vec3& sun : suns)
        for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest})
            for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8}) {
                ShadeParams p;
                p.sun = sun;
                p.filter = filter;
                p.storage = storage;
                p.sigma = 0.004f;
                const std::vector<float> plain = PlainShadeSweep(e, q, p);
                for (int threads : {1, 2, 5, 16}) {
                    const std::vector<float> banded = ShadeOnCpu(e, q, p, threads, std::nanf(""));
                    ASSERT_EQ(banded, plain) << threads << " threads, sun " << sun[0] << " " << sun[1] << " " << sun[2];
                }
                // Light must reach the far side partly: else the test is blind.
                ASSERT_GT(std::count_if(plain.begin(), plain.end(), [](float t) { return t > 0 && t < 1; }), 1000);
                ++compared;
            }
    EXPECT_EQ(compared, 54);
    for (int f : {2, 4}) {
        ShadeParams p;
        p.sun = SunDirection(0.3, 0.2);
        p.resolution = f;
        p.sigma = 0.004f;
        EXPECT_EQ(ShadeOnCpu(e, q, p, 16, std::nanf("")), ShadeOnCpu(e, q, p, 1)) << f;
    }
}

// Test that the CPU's sweep in shares ([0, 5), [5, 17), [17, end): tiles
// that start mid-sweep read the slice an earlier share wrote) equals the plain
// sweep on every principal axis, both sun signs, on 1, 2 and 16 threads.
TEST(Shade, CpuSharesEqualPlainSweep) {
    const Extent3 e{37, 29, 23};
    Pcg32 rng(17);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) ? float(rng.Below(65)) / 64.0f : 0.0f;
    int compared = 0;
    for (const Vec3& sun : {SunDirection(0.3, 0.2), SunDirection(0.3, 3.3), SunDirection(0.4, 1.4),
                            SunDirection(0.4, -1.7), SunDirection(1.1, 0.5), SunDirection(-1.2, 2.0)})
        for (int threads : {1, 2, 16}) {
            ShadeParams p;
            p.sun = sun;
            p.sigma = 0.004f;
            cpu::BackendCpu backend(threads);
            auto qb = test::MakeFilled(backend, BufferFormat::F32, e, q);
            auto T = test::MakeFilled(backend, BufferFormat::F32, e, std::vector<float>(e.Count(), std::nanf("")));
            for (SliceRange share : {SliceRange{0, 5}, SliceRange{5, 17}, SliceRange{17, UINT32_MAX}}) {
                p.slices = share;
                ASSERT_TRUE(backend.Shade(p, *qb, *T).has_value());
            }
            p.slices = {};
            ASSERT_EQ(test::Read<float>(backend, *T), PlainShadeSweep(e, q, p)) << threads << " threads, sun "
                                                                               << sun[0] << " " << sun[1];
            ++compared;
        }
    EXPECT_EQ(compared, 18);
}

// Test the CPU sweep's schedule on thesis-medium's grid (256 x 256 x 32) by
// hand. Sun at 25 degrees, azimuth 60: w = y, u = x (256), v = z (32), 256
// slices, taps at u0 = v0 = 0 (one band toward higher indices). On 2 threads
// v has 32 >= 4 * 2 rows: 2 bands of 16 rows, 4096 cells a slice, so 16384 /
// 4096 = 4 slices a tile; the longest chain is 1 fill tile plus all 256
// slices of one band: (4 + 256) * 4096 cells of 2^21. On 16 threads 32 < 64
// rows: 16 bands along u of 16 x 32 = 512 cells; 32 slices would fill 16384,
// but the fill (15 tiles) may take at most a quarter of the sweep, 256 / 60
// -> 4 slices; the chain is (15 * 4 + 256) * 512.
TEST(Shade, CpuScheduleByHand) {
    ShadeParams p;
    p.sun = SunDirection(25.0 * std::numbers::pi / 180.0, 60.0 * std::numbers::pi / 180.0);
    const ShadePlan plan = MakeShadePlan(p, Extent3{256, 256, 32});
    ASSERT_EQ(plan.geometry.w, 1);
    ASSERT_EQ(plan.geometry.u0, 0);
    ASSERT_EQ(plan.geometry.v0, 0);
    const cpu::ShadeSchedule one = cpu::MakeShadeSchedule(plan, 1, 0, 256);
    EXPECT_EQ(one.bands, 1u);
    EXPECT_EQ(one.span, one.work);
    const cpu::ShadeSchedule two = cpu::MakeShadeSchedule(plan, 2, 0, 256);
    EXPECT_EQ(two.axis, 1);
    EXPECT_EQ(two.bands, 2u);
    EXPECT_EQ(two.blockSlices, 4u);
    EXPECT_EQ(two.blocks, 64u);
    EXPECT_TRUE(two.towardHigher);
    EXPECT_EQ(two.work, 2097152.0);
    EXPECT_EQ(two.span, (4.0 + 256.0) * 4096.0);
    // 8 threads: 32 >= 4 * 8 rows, so 8 bands of 4 rows (1024 cells): 16 slices
    // would fill 16384, the fill (7 tiles) allows 256 / 28 -> 9.
    const cpu::ShadeSchedule eight = cpu::MakeShadeSchedule(plan, 8, 0, 256);
    EXPECT_EQ(eight.axis, 1);
    EXPECT_EQ(eight.bands, 8u);
    EXPECT_EQ(eight.blockSlices, 9u);
    EXPECT_EQ(eight.blocks, 29u);
    EXPECT_EQ(eight.span, (7.0 * 9.0 + 256.0) * 1024.0);
    const cpu::ShadeSchedule sixteen = cpu::MakeShadeSchedule(plan, 16, 0, 256);
    EXPECT_EQ(sixteen.axis, 0);
    EXPECT_EQ(sixteen.bands, 16u);
    EXPECT_EQ(sixteen.blockSlices, 4u);
    EXPECT_EQ(sixteen.span, (15.0 * 4.0 + 256.0) * 512.0);
    // A share of the sweep: slices [100, 140) on 2 threads, 40 slices, fill 1 tile of 4.
    const cpu::ShadeSchedule share = cpu::MakeShadeSchedule(plan, 2, 100, 140);
    EXPECT_EQ(share.blocks, 10u);
    EXPECT_EQ(share.span, (4.0 + 40.0) * 4096.0);
    // The sun at -x (azimuth 180 + 11 degrees, 17 high): s = (-0.94, -0.19,
    // 0.30), w = x, u = y, v = z, dv = 0.30 / 0.94 -> v0 = 0. Rows along y are
    // strided: bands of 2 rows (16 of them, on any thread count), tiles of 16
    // slices (a cache line of floats along x); the chain is 15 fill tiles of
    // 16 slices plus 256 slices, of 2 x 256 cells.
    p.sun = SunDirection(0.3, std::numbers::pi + 0.2);
    const ShadePlan west = MakeShadePlan(p, Extent3{256, 256, 32});
    ASSERT_EQ(west.geometry.w, 0);
    ASSERT_EQ(west.geometry.v0, 0);
    for (int threads : {1, 16}) {
        const cpu::ShadeSchedule x = cpu::MakeShadeSchedule(west, threads, 0, 256);
        EXPECT_EQ(x.axis, 1);
        EXPECT_EQ(x.bands, 16u);
        EXPECT_EQ(x.blockSlices, 16u);
        EXPECT_TRUE(x.towardHigher);
        EXPECT_EQ(x.span, (15.0 * 16.0 + 256.0) * 512.0);
    }
    // Sun at azimuth -80 degrees, 60 high: s = (0.09, -0.49, 0.87), w = z,
    // v = y, dv = -0.49 / 0.87 -> v0 = -1: each band reads the band below.
    p.sun = SunDirection(60.0 * std::numbers::pi / 180.0, -80.0 * std::numbers::pi / 180.0);
    const ShadePlan south = MakeShadePlan(p, Extent3{256, 256, 32});
    ASSERT_EQ(south.geometry.w, 2);
    ASSERT_EQ(south.geometry.v0, -1);
    const cpu::ShadeSchedule z2 = cpu::MakeShadeSchedule(south, 2, 0, 32);
    EXPECT_EQ(z2.axis, 1);
    EXPECT_FALSE(z2.towardHigher);
}

std::vector<float> ShadowOnCpu(const Extent3& e, const std::vector<float>& D, const ShadowParams& p) {
    cpu::BackendCpu backend;
    auto d = test::MakeFilled(backend, BufferFormat::F32, {e.nx, e.ny, 1}, D);
    auto G = test::MakeBuffer(backend, BufferFormat::F32, {e.nx, e.ny, 1});
    EXPECT_TRUE(backend.Shadow(p, *d, *G).has_value());
    return test::Read<float>(backend, *G);
}

// Test the ground shadow: overhead sun reads D straight above (exp(-sigma h D));
// a sun at 45 degrees in x reads D nz/2 cells toward +x; the thesis form is
// 1 - clamp(kappa D); no sun above the horizon gives 1.
TEST(Shadow, HandWorked) {
    const Extent3 e{10, 4, 8};
    std::vector<float> D(40, 0.0f);
    D[5 + 10 * 2] = 2.0f;
    ShadowParams p;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    p.nz = e.nz;
    p.sun = {0, 0, 1};
    std::vector<float> G = ShadowOnCpu(e, D, p);
    EXPECT_FLOAT_EQ(G[5 + 10 * 2], std::exp(-0.01f * 50 * 2.0f));
    EXPECT_EQ(G[4 + 10 * 2], 1.0f);
    const float s = std::sqrt(0.5f);
    p.sun = {s, 0, s};  // offset nz/2 = 4 cells toward +x
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[1 + 10 * 2], std::exp(-0.01f * 50 * 2.0f / s), 1e-6);
    EXPECT_EQ(G[5 + 10 * 2], 1.0f);
    p.form = ShadowForm::Thesis;
    p.kappa = 0.3f;
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[1 + 10 * 2], 1.0f - 0.6f, 1e-6);
    p.kappa = 1.0f;
    EXPECT_EQ(ShadowOnCpu(e, D, p)[1 + 10 * 2], 0.0f);  // clamped
    p.sun = {1, 0, 0};
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.sun = {0.6f, 0, -0.8f};
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.sun = SunDirection(1e-4, 0.0);  // grazing: finite
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_TRUE(std::isfinite(g));
}

// Test the lookup height where the hand-worked case above cannot (issue 17):
// an odd nz = 7 at 45 degrees along +x reads 3.5 cells over, so with only
// D(5, 2) = 2, cells 1 and 2 of row 2 read halfway between columns 4|5 and 5|6:
// D = 1 for both, G = exp(-sigma h / s_z); a lookup with nz/2 in integers reads
// 3 over (G = exp(-2 sigma h / s_z) at cell 2, 1 at cell 1). A sun along -y
// (nz = 8) reads 4 cells toward -y: cell (5, 6) reads D(5, 2).
TEST(Shadow, OddHeightAndMinusYHandWorked) {
    const Extent3 e{10, 8, 7};
    std::vector<float> D(80, 0.0f);
    D[5 + 10 * 2] = 2.0f;
    ShadowParams p;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    p.nz = e.nz;
    const float r = std::sqrt(0.5f);
    p.sun = {r, 0, r};
    std::vector<float> G = ShadowOnCpu(e, D, p);
    const float half = std::exp(-0.01f * 50 * 1.0f / r);
    EXPECT_NEAR(G[1 + 10 * 2], half, 1e-5);
    EXPECT_NEAR(G[2 + 10 * 2], half, 1e-5);
    EXPECT_NEAR(G[0 + 10 * 2], 1.0f, 1e-6);
    EXPECT_NEAR(G[3 + 10 * 2], 1.0f, 1e-6);
    EXPECT_NEAR(G[2 + 10 * 3], 1.0f, 1e-6);  // another row
    p.nz = 8;
    p.sun = {0, -r, r};
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[5 + 10 * 6], std::exp(-0.01f * 50 * 2.0f / r), 1e-5);
    EXPECT_NEAR(G[5 + 10 * 2], 1.0f, 1e-6);
    EXPECT_NEAR(G[5 + 10 * 5], 1.0f, 1e-5);
    EXPECT_NEAR(G[5 + 10 * 7], 1.0f, 1e-5);
    EXPECT_NEAR(G[4 + 10 * 6], 1.0f, 1e-6);
}

// Test Wang's form (seed 002 eq. 19, S = 1 - D_w max(T_S - (T_2D + 1 - C), 0))
// by hand, with T_S the column's opacity 1 - exp(-sigma h D / s_z) and T_2D = 0
// (docs/pipeline.md). D = 2, sigma h = 0.5: overhead tau = 1, opacity
// 1 - e^-1 = 0.632121; C = 0.8, D_w = 0.5: S = 1 - 0.5 (0.632121 - 0.2) = 0.783940.
// At 45 degrees tau = sqrt 2: S = 1 - 0.5 (1 - e^-1.414214 - 0.2) = 0.721558.
// Coverage 0.3: 1 - C = 0.7 is above the overhead opacity (no shadow) but below
// the slant one (S = 1 - 0.5 (0.756883 - 0.7) = 0.971558); C = D_w = 1 is plain
// exp(-tau) = 0.367879.
TEST(Shadow, WangHandWorked) {
    const Extent3 e{10, 4, 8};
    std::vector<float> D(40, 0.0f);
    D[5 + 10 * 2] = 2.0f;
    ShadowParams p;
    p.form = ShadowForm::Wang;
    p.sigma = 0.01f;
    p.voxelSize = 50;
    p.nz = e.nz;
    p.coverage = 0.8f;
    p.densityFactor = 0.5f;
    p.kappa = 5.0f;  // the thesis form's; Wang's ignores it
    p.sun = {0, 0, 1};
    std::vector<float> G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[5 + 10 * 2], 0.7839397f, 1e-6);
    EXPECT_EQ(G[4 + 10 * 2], 1.0f);  // no cloud: opacity 0, no shadow
    const float s = std::sqrt(0.5f);
    p.sun = {s, 0, s};  // offset nz/2 = 4 cells toward +x
    G = ShadowOnCpu(e, D, p);
    EXPECT_NEAR(G[1 + 10 * 2], 0.7215584f, 1e-6);
    EXPECT_EQ(G[5 + 10 * 2], 1.0f);
    p.coverage = 0.3f;  // slant opacity 0.756883 still exceeds 1 - C = 0.7
    EXPECT_NEAR(ShadowOnCpu(e, D, p)[1 + 10 * 2], 0.9715584f, 1e-6);
    p.sun = {0, 0, 1};  // overhead opacity 0.632121 does not
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.coverage = 1.0f;
    p.densityFactor = 1.0f;
    EXPECT_NEAR(ShadowOnCpu(e, D, p)[5 + 10 * 2], 0.3678794f, 1e-6);
    p.densityFactor = 0.0f;  // no density: no shadow
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
    p.sun = {0.6f, 0, -0.8f};  // no sun above the horizon
    p.densityFactor = 1.0f;
    for (float g : ShadowOnCpu(e, D, p)) EXPECT_EQ(g, 1.0f);
}

}  // namespace
}  // namespace cb
