// The dual-lobe phase function (core/math/Shading.h PhaseValue, PhaseKind::DualLobe): against its closed
// form in double, its ends (a blend of 0 or 1 is one lobe, bit for bit), its normalisation, its peak, and
// the scene fields that set it (phase.g_forward, phase.g_backward, phase.blend).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "SceneTestUtil.h"
#include "core/math/Shading.h"
#include "core/scene/Scene.h"

namespace cb {
namespace {

using test::ErrorOf;
using test::HasLine;
using test::Parsed;

PhaseParams DualLobe(float gForward, float gBackward, float blend) {
    PhaseParams p;
    p.kind = PhaseKind::DualLobe;
    p.g = 0.123f;  // read by no lobe
    p.gForward = gForward;
    p.gBackward = gBackward;
    p.blend = blend;
    return p;
}

// 4 pi p of Henyey-Greenstein in double, written from the formula, not from the code.
double HgDouble(double g, double c) { return (1 - g * g) / std::pow(1 + g * g - 2 * g * c, 1.5); }

// The settings measured in reports/march/dual-lobe.md: the default (Hillaire 2016), a milder forward lobe, and
// a strong backward one whose peak is at cos = -1.
struct Setting {
    float gForward, gBackward, blend;
};
const Setting kSettings[] = {{0.8f, -0.5f, 0.5f}, {0.5f, -0.5f, 0.5f}, {0.85f, -0.3f, 0.2f},
                             {0.3f, -0.9f, 0.9f}, {0.0f, 0.0f, 0.5f},  {0.9f, -0.2f, 0.1f}};

// Test the value at hand-worked points of the default (0.8, -0.5, 1/2): at cos 1, 1/2 (1.8/0.04) + 1/2 (0.5/2.25)
// = 22.6111; at cos -1, 1/2 (0.2/3.24) + 1/2 (1.5/0.25) = 3.03086; at cos 0, 1/2 (0.36/1.64^1.5) +
// 1/2 (0.75/1.25^1.5) = 0.35404.
TEST(DualLobe, HandWorkedDefault) {
    const PhaseParams p = DualLobe(kDualLobeGForward, kDualLobeGBackward, kDualLobeBlend);
    EXPECT_NEAR(PhaseValue(p, 1.0f), 0.5 * 1.8 / 0.04 + 0.5 * 0.5 / 2.25, 2e-4);
    EXPECT_NEAR(PhaseValue(p, -1.0f), 0.5 * 0.2 / 3.24 + 0.5 * 1.5 / 0.25, 2e-5);
    EXPECT_NEAR(PhaseValue(p, 0.0f), 0.5 * 0.36 / std::pow(1.64, 1.5) + 0.5 * 0.75 / std::pow(1.25, 1.5), 1e-6);
    // The defaults are what a PhaseParams starts with.
    const PhaseParams fresh;
    EXPECT_EQ(fresh.gForward, 0.8f);
    EXPECT_EQ(fresh.gBackward, -0.5f);
    EXPECT_EQ(fresh.blend, 0.5f);
}

// Test the float value against (1 - w) HG(g_f) + w HG(g_b) in double at 4001 cosines of every setting: within the
// float rounding of the denominator 1 + g^2 - 2 g cos (relative 2^-22 (1 + g^2 + 2|g|) / denom, times 1.5 for the
// power) plus a few ulps.
TEST(DualLobe, MatchesTheClosedFormInDouble) {
    for (const Setting& s : kSettings) {
        const PhaseParams p = DualLobe(s.gForward, s.gBackward, s.blend);
        for (int i = 0; i <= 4000; ++i) {
            const float c = -1.0f + float(i) / 2000.0f;
            const double f = s.gForward, b = s.gBackward, w = s.blend;
            const double exact = (1 - w) * HgDouble(f, c) + w * HgDouble(b, c);
            auto lobeError = [c](double g) {
                const double denom = 1 + g * g - 2 * g * c;
                return 1.5 * std::ldexp(1.0, -22) * (1 + g * g + 2 * std::fabs(g)) / denom * HgDouble(g, c);
            };
            const double bound = (1 - w) * lobeError(f) + w * lobeError(b) + 8 * std::ldexp(exact, -23);
            EXPECT_NEAR(PhaseValue(p, c), exact, bound)
                << "g_f " << s.gForward << ", g_b " << s.gBackward << ", w " << s.blend << ", cos " << c;
        }
    }
}

// Test the ends of the blend: w = 0 is Henyey-Greenstein of g_forward and w = 1 of g_backward, bit for bit, at every
// cosine of a fine grid and at +-1 (a lobe of weight 0 adds an exact 0).
TEST(DualLobe, BlendEndsAreOneLobeBitForBit) {
    for (const Setting& s : kSettings)
        for (int i = 0; i <= 20000; ++i) {
            const float c = std::clamp(-1.0f + float(i) / 10000.0f, -1.0f, 1.0f);
            EXPECT_EQ(PhaseValue(DualLobe(s.gForward, s.gBackward, 0.0f), c),
                      PhaseValue({PhaseKind::HenyeyGreenstein, s.gForward}, c))
                << s.gForward << " at cos " << c;
            EXPECT_EQ(PhaseValue(DualLobe(s.gForward, s.gBackward, 1.0f), c),
                      PhaseValue({PhaseKind::HenyeyGreenstein, s.gBackward}, c))
                << s.gBackward << " at cos " << c;
        }
}

// Test the normalisation: the mean of P^ over the sphere, (1/2) of its integral over cos in [-1, 1], is 1 (the
// midpoint rule with 400000 nodes; its error for the sharpest lobe here, g 0.9, is below 1e-6).
TEST(DualLobe, AveragesToOneOverTheSphere) {
    for (const Setting& s : kSettings) {
        const PhaseParams p = DualLobe(s.gForward, s.gBackward, s.blend);
        const int n = 400000;
        double sum = 0;
        for (int i = 0; i < n; ++i) sum += PhaseValue(p, float(-1.0 + 2.0 * (i + 0.5) / n));
        EXPECT_NEAR(sum / n, 1.0, 1e-4) << s.gForward << " " << s.gBackward << " " << s.blend;
    }
}

// Test PhasePeak: it is the larger of the two ends, it is cos = -1 where the backward lobe dominates, and no float
// cosine in [-1, 1] (a grid of 2^21 + 1 and every float within 64 ulps of the ends and of 0) evaluates above it by
// more than 2 ulps (the blend of two convex lobes is largest at an end; rounding may lift a nearly flat blend: 1 ulp
// for (0.2, -0.2, 1/2) at cos = -1 + 2^-22, every float near the ends searched).
TEST(DualLobe, PeakIsAtAnEnd) {
    std::vector<Setting> settings(std::begin(kSettings), std::end(kSettings));
    settings.push_back({0.2f, -0.2f, 0.5f});
    settings.push_back({0.01f, -0.01f, 0.5f});
    for (const Setting& s : settings) {
        const PhaseParams p = DualLobe(s.gForward, s.gBackward, s.blend);
        const float peak = PhasePeak(p);
        EXPECT_EQ(peak, std::max(PhaseValue(p, 1.0f), PhaseValue(p, -1.0f)));
        std::vector<float> cosines;
        for (int i = 0; i <= (1 << 21); ++i) cosines.push_back(-1.0f + float(i) / float(1 << 20));
        for (float end : {1.0f, -1.0f, 0.0f}) {
            float up = end, down = end;
            for (int k = 0; k < 64; ++k) {
                up = std::nextafter(up, 2.0f), down = std::nextafter(down, -2.0f);
                if (up <= 1.0f) cosines.push_back(up);
                if (down >= -1.0f) cosines.push_back(down);
            }
        }
        float largest = 0;
        for (float c : cosines) largest = std::max(largest, PhaseValue(p, std::clamp(c, -1.0f, 1.0f)));
        EXPECT_LE(largest, std::nextafter(std::nextafter(peak, 1e30f), 1e30f))
            << s.gForward << " " << s.gBackward << " " << s.blend;
    }
    // Backward-dominated: 0.1 HG(0.3) + 0.9 HG(-0.9) peaks at cos -1, 0.1 (0.7/1.69) + 0.9 (1.9/0.01) = 171.04.
    const PhaseParams back = DualLobe(0.3f, -0.9f, 0.9f);
    EXPECT_EQ(PhasePeak(back), PhaseValue(back, -1.0f));
    EXPECT_NEAR(PhasePeak(back), 0.1 * 0.7 / 1.69 + 0.9 * 1.9 / 0.01, 0.05);
}

// ---- The scene fields ----------------------------------------------------------------------------------------

// Test that dual-lobe reads its three fields, and that without them it takes the defaults.
TEST(DualLobe, SceneReadsItsFields) {
    const Scene set = Parsed(R"({"grid": {"size": [8, 4, 6]},
        "phase": {"function": "dual-lobe", "g_forward": 0.7, "g_backward": -0.25, "blend": 0.3}})");
    EXPECT_EQ(set.phase.kind, PhaseKind::DualLobe);
    EXPECT_EQ(set.phase.gForward, 0.7f);
    EXPECT_EQ(set.phase.gBackward, -0.25f);
    EXPECT_EQ(set.phase.blend, 0.3f);
    const Scene plain = Parsed(R"({"grid": {"size": [8, 4, 6]}, "phase": {"function": "dual-lobe"}})");
    EXPECT_EQ(plain.phase.gForward, kDualLobeGForward);
    EXPECT_EQ(plain.phase.gBackward, kDualLobeGBackward);
    EXPECT_EQ(plain.phase.blend, kDualLobeBlend);
    // The ranges' closed ends are accepted: a forward lobe of 0, a backward lobe of 0, blends of 0 and 1.
    const Scene ends = Parsed(R"({"grid": {"size": [8, 4, 6]},
        "phase": {"function": "dual-lobe", "g_forward": 0, "g_backward": 0, "blend": 1}})");
    EXPECT_EQ(ends.phase.gForward, 0.0f);
    EXPECT_EQ(ends.phase.blend, 1.0f);
    // As phase.g is read with every function, so are the lobes (only dual-lobe uses them).
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "phase": {"function": "mie", "blend": 0.25}})").phase.blend,
              0.25f);
}

// Test each field's refusals: out of its range, on the open end, a value that reaches +-1 only as a float, a string,
// and a lobe whose own peak passes 2^18 even with a weight of 0.
TEST(DualLobe, SceneRefusesBadFields) {
    auto error = [](const std::string& phase) {
        return ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "phase": {"function": "dual-lobe", )" + phase + "}}");
    };
    EXPECT_TRUE(HasLine(error(R"("g_forward": -0.1)"), "test.json: phase.g_forward: must be in [0, 1), got -0.1"));
    EXPECT_TRUE(HasLine(error(R"("g_forward": 1)"), "test.json: phase.g_forward: must be in [0, 1), got 1"));
    EXPECT_TRUE(HasLine(error(R"("g_forward": 0.99999999999)"),
                        "test.json: phase.g_forward: must be in [0, 1) in single precision, got 0.99999999999"));
    EXPECT_TRUE(HasLine(error(R"("g_backward": 0.2)"), "test.json: phase.g_backward: must be in (-1, 0], got 0.2"));
    EXPECT_TRUE(HasLine(error(R"("g_backward": -1)"), "test.json: phase.g_backward: must be in (-1, 0], got -1"));
    EXPECT_TRUE(HasLine(error(R"("blend": 1.5)"), "test.json: phase.blend: must be in [0, 1], got 1.5"));
    EXPECT_TRUE(HasLine(error(R"("blend": -0.5)"), "test.json: phase.blend: must be in [0, 1], got -0.5"));
    EXPECT_TRUE(HasLine(error(R"("blend": "half")"), R"(test.json: phase.blend: expected a number, got "half")"));
    // HG(0.999) at cos 1 is 1.999 / 1e-6, about 2e6 > 2^18; refused though its weight is 0 (0 * inf would be NaN).
    const std::string peak = error(R"("g_forward": 0.999, "blend": 1)");
    EXPECT_TRUE(peak.find("test.json: phase.g_forward: the lobe's peak (Henyey-Greenstein at cos theta = 1") !=
                std::string::npos)
        << peak;
    const std::string backPeak = error(R"("g_backward": -0.999)");
    EXPECT_TRUE(backPeak.find("test.json: phase.g_backward: the lobe's peak (Henyey-Greenstein at cos theta = -1") !=
                std::string::npos)
        << backPeak;
    // A lobe just within the bound is accepted: HG(0.99) at cos 1 is about 1.99e4.
    EXPECT_EQ(Parsed(R"({"grid": {"size": [8, 4, 6]}, "phase": {"function": "dual-lobe", "g_forward": 0.99}})")
                  .phase.gForward,
              0.99f);
}

}  // namespace
}  // namespace cb
