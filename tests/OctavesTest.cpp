// Multiple-scattering octaves (core/math/Light.h SunPhases and SunGain; lighting.octaves): the sun's gain against
// the sum written out here in double, one octave against single scattering bit for bit, and the exact reference
// render of a homogeneous slab against the closed form of each octave's integral. Expected values come from the
// formulas of the definition, never from the code under test.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/math/Light.h"
#include "core/math/March.h"
#include "core/pipeline/LightTerms.h"
#include "reference/MarchReference.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

double Hg(double g, double cosTheta) { return (1 - g * g) / std::pow(1 + g * g - 2 * g * cosTheta, 1.5); }

LightTerms Octaves(uint32_t n, float a, float b, float c, PhaseKind kind = PhaseKind::HenyeyGreenstein) {
    LightTerms L;
    L.phase.kind = kind;
    L.phase.g = 0.6f;
    L.octaves = n;
    L.octaveAttenuation = a;
    L.octaveContribution = b;
    L.octaveEccentricity = c;
    return L;
}

// sum_i b^i HG(g c^i, cos) T^(a^i), in double.
double GainByHand(uint32_t n, double a, double b, double c, double g, double cosTheta, double T) {
    double sum = 0;
    for (uint32_t i = 0; i < n; ++i)
        sum += std::pow(b, i) * Hg(g * std::pow(c, i), cosTheta) * std::pow(T, std::pow(a, i));
    return sum;
}

TEST(Octaves, SunGainIsTheSumOfTheOctaves) {
    Pcg32 rng(0x0c7a);
    for (int k = 0; k < 2000; ++k) {
        const uint32_t n = 1 + rng.Below(kMaxOctaves);
        const float a = float(rng.Uniform(0.05, 1)), b = float(rng.Uniform(a, 1)), c = float(rng.Uniform(0, 1));
        const float cosTheta = float(rng.Uniform(-1, 1)), T = float(rng.Uniform(0, 1));
        const LightTerms L = Octaves(n, a, b, c);
        const double want = GainByHand(n, a, b, c, L.phase.g, cosTheta, T);
        const float got = SunGain(L, MakeSunPhases(L, cosTheta), T);
        EXPECT_NEAR(got, want, 2e-6 * std::max(1.0, want)) << "n " << n << " a " << a << " b " << b << " c " << c;
    }
    // Hand-worked: n = 3, a = b = c = 1/2, g = 0.6, cos 0 (HG(g, 0) = (1 - g^2) / (1 + g^2)^1.5), T = 1/4:
    // 1/4 * 0.64 / 1.36^1.5 + 1/2 * 0.91 / 1.09^1.5 * 1/2 + 1/4 * 0.9775 / 1.0225^1.5 * 1/4^(1/4).
    const double hand = 0.25 * 0.64 / std::pow(1.36, 1.5) + 0.25 * 0.91 / std::pow(1.09, 1.5) +
                        0.25 * 0.9775 / std::pow(1.0225, 1.5) / std::sqrt(2.0);
    const LightTerms L = Octaves(3, 0.5f, 0.5f, 0.5f);
    EXPECT_NEAR(SunGain(L, MakeSunPhases(L, 0.0f), 0.25f), hand, 1e-6);
}

TEST(Octaves, OneOctaveIsSingleScatteringBitForBit) {
    Pcg32 rng(0x10c7);
    for (PhaseKind kind : {PhaseKind::None, PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks, PhaseKind::Mie,
                           PhaseKind::DualLobe}) {
        const LightTerms L = Octaves(1, 0.3f, 0.7f, 0.2f, kind);  // a, b, c unread with one octave
        for (int k = 0; k < 500; ++k) {
            const float cosTheta = float(rng.Uniform(-1, 1)), T = float(rng.Uniform(0, 1));
            EXPECT_EQ(SunGain(L, MakeSunPhases(L, cosTheta), T), T * PhaseValue(L.phase, cosTheta));
        }
    }
}

TEST(Octaves, EccentricityScalesEveryLobeAndNoneStaysOne) {
    LightTerms L = Octaves(3, 0.5f, 0.5f, 0.5f, PhaseKind::DualLobe);
    L.phase.gForward = 0.8f, L.phase.gBackward = -0.4f, L.phase.blend = 0.25f;
    const SunPhases p = MakeSunPhases(L, 0.3f);
    for (int i = 0; i < 3; ++i) {
        const double s = std::pow(0.5, i);
        EXPECT_NEAR(p.value[i], 0.75 * Hg(0.8 * s, 0.3) + 0.25 * Hg(-0.4 * s, 0.3), 1e-5) << i;
    }
    const LightTerms none = Octaves(4, 0.5f, 0.5f, 0.5f, PhaseKind::None);
    const SunPhases q = MakeSunPhases(none, -0.7f);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(q.value[i], 1.0f);
}

// A slab of constant q0 seen from inside (tests/MarchReferenceTest.cpp derives the single-scattering forms): with
// octaves the sun's term is the sum over i of b^i P^_i times
// - sun straight behind the camera, light depth q0 (c + t): e^{-a^i s q0 c} (1 - e^{-(1 + a^i) s q0 D}) / (1 + a^i),
//   at cos theta = -1;
// - sun overhead, a horizontal view, constant depth q0 c: e^{-a^i s q0 c} (1 - e^{-s q0 D}), at cos theta = 0.
TEST(Octaves, ReferenceRenderOfASlabMatchesTheClosedForm) {
    const Extent3 e{8, 8, 24};
    const float q0 = 0.8f;
    const std::vector<float> q(e.Count(), q0);
    struct Case {
        std::array<double, 3> eye, target, up;
        Vec3 sun;
        double D, c, cosTheta;
        bool linear;
    };
    const Case cases[] = {{{4, 4, 2}, {4, 4, 20}, {0, 1, 0}, {0, 0, -1}, 20.0, 1.5 + 0.375, -1.0, true},
                          {{0.75, 4, 12}, {8, 4, 12}, {0, 0, 1}, {0, 0, 1}, 6.5, 11.5 + 0.375, 0.0, false}};
    const float step = 0.125f;
    for (const Case& k : cases) {
        CameraSettings cam;
        cam.eye = k.eye, cam.target = k.target, cam.up = k.up;
        cam.fovDeg = 40, cam.nearPlane = 1e-4, cam.farPlane = k.D;
        MarchParams p;
        p.camera = MakeCameraFrame(cam, 1, 1);
        p.setup.size = {float(e.nx), float(e.ny), float(e.nz)};
        p.setup.sigmaH = 0.1f;
        p.setup.sun = k.sun;
        p.setup.light = Octaves(4, 0.5f, 0.7f, 0.5f);
        p.setup.light.sunRadiance = {1.0f, 0.8f, 0.6f};
        ref::MarchReferenceOptions o;
        o.stepVoxels = step;
        auto r = ref::RenderMarchReference(p, e, q, q, o);
        ASSERT_TRUE(r.has_value()) << r.error().message;
        const double s = p.setup.sigmaH, x = s * q0;
        double sunTerm = 0;
        for (int i = 0; i < 4; ++i) {
            const double ai = std::pow(0.5, i), P = std::pow(0.7, i) * Hg(0.6 * std::pow(0.5, i), k.cosTheta);
            sunTerm += P * std::exp(-ai * x * k.c) *
                       (k.linear ? (1 - std::exp(-(1 + ai) * x * k.D)) / (1 + ai) : 1 - std::exp(-x * k.D));
        }
        // The midpoint sum's factor 1/cosh(y/2) >= 1 - y^2/8 per segment, y = (1 + a^i) s q0 step <= 2 s q0 step.
        const double y = 2 * x * step;
        for (int ch = 0; ch < 3; ++ch) {
            const double want = p.setup.light.sunRadiance[ch] * sunTerm;
            EXPECT_NEAR(r->image[ch], want, want * (k.linear ? y * y / 8 : 0) + 1e-5 * want + 2e-6)
                << (k.linear ? "behind" : "overhead") << " channel " << ch;
        }
    }
}

}  // namespace
}  // namespace cb
