// The math light attenuation (SPEC 6) and the ground shadow (SPEC 7) share:
// the vectorisable exp, half and unorm8 rounding and the stored codes, the
// principal axis rule and the phase functions.
#include <gtest/gtest.h>
#include <immintrin.h>

#include <cmath>
#include <cstdint>

#include "core/math/Shading.h"

namespace cb {
namespace {

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

// The CPU's F16C conversion there and back (the build is for baseline x86-64:
// called only where the CPU has F16C).
__attribute__((target("f16c"))) float HalfByF16C(float v) { return _cvtsh_ss(_cvtss_sh(v, _MM_FROUND_TO_NEAREST_INT)); }

// Test the software float -> half rounding against the CPU's F16C conversion
// (round to nearest even) on every float in [0, 1] with a step of 2^-20 and
// on every value near half's subnormal boundary.
TEST(ShadingMath, RoundToHalfMatchesF16C) {
    if (!__builtin_cpu_supports("f16c")) GTEST_SKIP() << "unsupported here: no F16C";
    auto hardware = HalfByF16C;
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
    // The H200's case (214/255 against 215/255 as the GPU rounded them): neighbouring codes
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

}  // namespace
}  // namespace cb
