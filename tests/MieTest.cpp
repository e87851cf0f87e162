// Lorenz-Mie scattering (core/math/Mie.h) and the project's Mie phase table (SPEC 9;
// docs/pipeline.md, "Mie phase table").
//
// Sources of the expected values:
// - Bohren & Huffman, "Absorption and Scattering of Light by Small Particles"
//   (Wiley 1983), appendix A, the sample output of BHMIE: a sphere of radius
//   0.525 um at 0.6328 um (x = 5.213), m = 1.55: Q_ext = Q_sca = 3.10543,
//   Q_back = 2.92534.
// - Wiscombe, "Mie scattering calculations: advances in technique and fast,
//   vector-speed computer codes", NCAR/TN-140+STR (1979, rev. 1996), the MIEV0
//   test cases: m = 0.75, x = 0.099: Q_ext = Q_sca = 7.417859e-6;
//   m = 1.5, x = 10: Q_ext = Q_sca = 2.881999.
// - tests/mie_reference.py: an independent implementation (the defining
//   formulas of a_n, b_n with scipy's spherical Bessel functions, Legendre
//   polynomials for pi_n and tau_n, Q_sca and g by quadrature of |S|^2 over the
//   sphere, Q_ext by the optical theorem). It reproduces the three published
//   cases above to every printed digit.
// - Closed forms: the Rayleigh limit (Bohren & Huffman section 5.2), the
//   extinction paradox (van de Hulst 1957, Q_ext -> 2), normalisation.
// - Literature on cloud droplets: g about 0.85-0.87 for cumulus in the visible
//   (Hansen & Travis 1974), the fog bow near 140 degrees and the glory at 180.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "core/math/Mie.h"
#include "core/math/Shading.h"

namespace cb {
namespace {

using MieComplex = std::complex<double>;
constexpr double kMiePi = std::numbers::pi;

double MieDeg(double degrees) { return degrees * kMiePi / 180.0; }

// Test that the published values of Bohren-Huffman and Wiscombe are reproduced.
TEST(Mie, PublishedSingleSphereValues) {
    {
        const mie::Efficiencies e =
            mie::ComputeEfficiencies(mie::ComputeCoefficients(2 * kMiePi * 0.525 / 0.6328, {1.55, 0}));
        EXPECT_NEAR(e.qExt, 3.10543, 1e-5);
        EXPECT_NEAR(e.qSca, 3.10543, 1e-5);
        EXPECT_NEAR(e.qBack, 2.92534, 1e-5);
    }
    {
        const mie::Efficiencies e = mie::ComputeEfficiencies(mie::ComputeCoefficients(0.099, {0.75, 0}));
        EXPECT_NEAR(e.qExt, 7.417859e-6, 1e-12);
        EXPECT_NEAR(e.qSca, 7.417859e-6, 1e-12);
    }
    {
        const mie::Efficiencies e = mie::ComputeEfficiencies(mie::ComputeCoefficients(10, {1.5, 0}));
        EXPECT_NEAR(e.qExt, 2.881999, 1e-6);
        EXPECT_NEAR(e.qSca, 2.881999, 1e-6);
    }
}

// The rows printed by tests/mie_reference.py: x, m, Q_ext, Q_sca, Q_back, g,
// and P^ at 0, 30, 90, 140 and 180 degrees.
struct MieReferenceCase {
    double x;
    MieComplex m;
    double qExt, qSca, qBack, g;
    double phase[5];
};
constexpr double kMieReferenceAngles[5] = {0, 30, 90, 140, 180};
const MieReferenceCase kMieReference[] = {
    {0.5,
     {1.33, 0},
     0.00677313988,
     0.00677313988,
     0.00907253577,
     0.0454647818,
     {1.66918881, 1.4421655, 0.748417524, 1.08753624, 1.33948743}},
    {1,
     {1.33, 0},
     0.0939240012,
     0.0939240012,
     0.0846252648,
     0.184516674,
     {2.24069599, 1.86711555, 0.724012061, 0.788623744, 0.900997228}},
    {10,
     {1.33, 0},
     2.20654871,
     2.20654871,
     0.56117943,
     0.71245927,
     {64.7883138, 4.0137651, 0.151952817, 0.347325866, 0.254324515}},
    {30,
     {1.33, 0},
     1.99840984,
     1.99840984,
     0.395958002,
     0.826938666,
     {461.624686, 2.31615813, 0.0626219413, 0.0901373593, 0.198136535}},
    {3,
     {1.55, 0},
     3.70220135,
     3.70220135,
     0.802728345,
     0.707863653,
     {9.96730834, 4.87207615, 0.15505634, 0.137575973, 0.216824605}},
    {5,
     {1.5, 0.1},
     3.15369353,
     1.96346816,
     0.139849045,
     0.836154345,
     {31.7658774, 1.86325322, 0.134728534, 0.072158033, 0.0712255223}},
    {10,
     {1.33, 0.05},
     2.36406361,
     1.33084807,
     0.0634489535,
     0.865184611,
     {108.179951, 2.84445511, 0.0675213375, 0.0736127621, 0.0476755798}},
};

// Test water-like, glass-like and absorbing spheres against the independent implementation.
TEST(Mie, MatchesIndependentImplementation) {
    for (const MieReferenceCase& r : kMieReference) {
        SCOPED_TRACE("x = " + std::to_string(r.x) + ", m = " + std::to_string(r.m.real()) + " + " +
                     std::to_string(r.m.imag()) + "i");
        const mie::Coefficients c = mie::ComputeCoefficients(r.x, r.m);
        const mie::Efficiencies e = mie::ComputeEfficiencies(c);
        // The reference is printed to 9 significant digits.
        EXPECT_NEAR(e.qExt, r.qExt, 1e-8 * r.qExt);
        EXPECT_NEAR(e.qSca, r.qSca, 1e-8 * r.qSca);
        EXPECT_NEAR(e.qBack, r.qBack, 1e-8 * r.qBack);
        EXPECT_NEAR(e.g, r.g, 1e-8);
        std::vector<double> mu;
        for (double a : kMieReferenceAngles) mu.push_back(std::cos(MieDeg(a)));
        const std::vector<double> p = mie::SpherePhase(c, mu);
        for (size_t k = 0; k < mu.size(); ++k)
            EXPECT_NEAR(p[k], r.phase[k], 1e-8 * r.phase[k]) << kMieReferenceAngles[k];
    }
}

// Test the optical theorem (Q_ext = 4 Re S(0) / x^2, S1(0) = S2(0)) and that
// a sphere without absorption scatters all it removes (Q_ext = Q_sca).
TEST(Mie, OpticalTheoremAndNoAbsorption) {
    for (double x : {0.3, 4.0, 40.0, 400.0}) {
        const mie::Coefficients c = mie::ComputeCoefficients(x, {1.333, 0});
        const mie::Efficiencies e = mie::ComputeEfficiencies(c);
        const double forward[1] = {1.0};
        const mie::Amplitudes s = mie::ComputeAmplitudes(c, forward)[0];
        EXPECT_NEAR(std::abs(s.s1 - s.s2), 0.0, 1e-12 * std::abs(s.s1)) << x;
        EXPECT_NEAR(4.0 * s.s1.real() / (x * x), e.qExt, 1e-10 * e.qExt) << x;
        EXPECT_NEAR(e.qSca, e.qExt, 1e-10 * e.qExt) << x;
    }
    const mie::Efficiencies absorbing = mie::ComputeEfficiencies(mie::ComputeCoefficients(20, {1.33, 0.01}));
    EXPECT_LT(absorbing.qSca, absorbing.qExt);
}

// Test the Rayleigh limit: Q_sca = (8/3) x^4 |K|^2, Q_abs = 4 x Im K with
// K = (m^2 - 1)/(m^2 + 2), and P^ = (3/4)(1 + cos^2) (corrections are O(x^2)).
TEST(Mie, RayleighLimit) {
    const double x = 0.01;
    for (MieComplex m : {MieComplex(1.33, 0), MieComplex(1.5, 0.1), MieComplex(2.0, 1.0)}) {
        const MieComplex K = (m * m - 1.0) / (m * m + 2.0);
        const mie::Coefficients c = mie::ComputeCoefficients(x, m);
        const mie::Efficiencies e = mie::ComputeEfficiencies(c);
        const double qSca = 8.0 / 3.0 * std::pow(x, 4) * std::norm(K);
        EXPECT_NEAR(e.qSca, qSca, 1e-3 * qSca);
        if (m.imag() > 0) {
            EXPECT_NEAR(e.qExt - e.qSca, 4 * x * K.imag(), 1e-3 * 4 * x * K.imag());
        }
        EXPECT_NEAR(e.g, 0.0, 1e-3);
        std::vector<double> mu;
        for (double a = 0; a <= 180; a += 15) mu.push_back(std::cos(MieDeg(a)));
        const std::vector<double> p = mie::SpherePhase(c, mu);
        for (size_t k = 0; k < mu.size(); ++k) EXPECT_NEAR(p[k], 0.75 * (1 + mu[k] * mu[k]), 1e-3) << mu[k];
    }
}

// Test the extinction paradox: Q_ext -> 2 for large spheres (van de Hulst),
// within the edge term ~2 x^(-2/3) plus ripple.
TEST(Mie, LargeSphereExtinctionTendsToTwo) {
    for (double x : {1000.0, 5000.0}) {
        const mie::Efficiencies e = mie::ComputeEfficiencies(mie::ComputeCoefficients(x, {1.33, 0}));
        EXPECT_NEAR(e.qExt, 2.0, 4.0 * std::pow(x, -2.0 / 3.0)) << x;
        EXPECT_GT(e.qExt, 2.0) << x;
    }
}

// Composite Simpson of (1/2) Int_0^pi f(theta) sin(theta) dtheta with n (even) intervals.
template <typename F>
double MieSphereAverage(F f, int n) {
    const double h = kMiePi / n;
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
        const double t = h * i;
        const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        sum += w * f(t) * std::sin(t);
    }
    return 0.5 * sum * h / 3.0;
}

// Test that one sphere's P^ averages to 1 over the sphere and that its mean
// cosine is the g of the series formula.
TEST(Mie, SpherePhaseIsNormalised) {
    const mie::Coefficients c = mie::ComputeCoefficients(25, {1.33, 0});
    const int n = 4000;
    std::vector<double> mu(n + 1);
    for (int i = 0; i <= n; ++i) mu[i] = std::cos(kMiePi * i / n);
    const std::vector<double> p = mie::SpherePhase(c, mu);
    auto at = [&](double t) { return p[size_t(std::lround(t / (kMiePi / n)))]; };
    EXPECT_NEAR(MieSphereAverage(at, n), 1.0, 1e-6);
    EXPECT_NEAR(MieSphereAverage([&](double t) { return at(t) * std::cos(t); }, n), mie::ComputeEfficiencies(c).g,
                1e-6);
}

// Test that Henyey-Greenstein and Cornette-Shanks average to 1 over the sphere
// (quadrature in theta, where ShadeTest uses uniform cosines).
TEST(Mie, AnalyticPhaseFunctionsAreNormalised) {
    for (PhaseKind kind : {PhaseKind::HenyeyGreenstein, PhaseKind::CornetteShanks})
        for (float g : {-0.5f, 0.0f, 0.6f, 0.9f}) {
            const double avg = MieSphereAverage(
                [&](double t) {
                    return double(PhaseValue({kind, g}, float(std::cos(t))));
                },
                200000);
            EXPECT_NEAR(avg, 1.0, 1e-4) << int(kind) << " g " << g;
        }
}

// Test the linear sampler on a table that is linear in theta (so exact), at the ends and between nodes.
TEST(Mie, SamplePhaseTableIsLinearInTheta) {
    std::vector<float> values(181);
    for (size_t i = 0; i < values.size(); ++i) values[i] = float(i);  // value = theta in degrees
    const PhaseTable table{values.data(), uint32_t(values.size()), float(180.0 / kMiePi)};
    EXPECT_EQ(SamplePhaseTable(table, 1.0f), 0.0f);
    EXPECT_NEAR(SamplePhaseTable(table, -1.0f), 180.0f, 1e-4f);
    EXPECT_NEAR(SamplePhaseTable(table, 2.0f), 0.0f, 1e-6f);     // clamped
    EXPECT_NEAR(SamplePhaseTable(table, -2.0f), 180.0f, 1e-4f);  // clamped
    for (double deg : {0.25, 12.5, 89.9, 90.0, 137.3, 179.75})
        EXPECT_NEAR(SamplePhaseTable(table, float(std::cos(MieDeg(deg)))), deg, 2e-3) << deg;
}

// ArcCos (Abramowitz & Stegun 4.4.46 in float) against the double-precision
// library acos: within 1e-6 rad everywhere on [-1, 1], exact-ish at the ends.
TEST(Mie, ArcCosMatchesTheLibraryWithinAMicroradian) {
    double worst = 0;
    for (int i = -100000; i <= 100000; ++i) {
        const float x = float(i) / 100000.0f;
        worst = std::max(worst, std::fabs(double(ArcCos(x)) - std::acos(double(x))));
    }
    EXPECT_LT(worst, 1e-6);
    EXPECT_NEAR(ArcCos(1.0f), 0.0, 1e-7);
    EXPECT_NEAR(ArcCos(0.0f), kMiePi / 2, 1e-7);
    EXPECT_NEAR(ArcCos(-1.0f), kMiePi, 3e-7);
    EXPECT_NEAR(ArcCos(0.5f), kMiePi / 3, 1e-6);
    EXPECT_NEAR(ArcCos(-0.5f), 2 * kMiePi / 3, 1e-6);
}

std::span<const float> MieCloudValues() { return {kMieCloudTable.values, kMieCloudTable.count}; }

// P^ of the table at theta (degrees), through PhaseValue as every stage calls it.
double MieTableAt(double deg) { return PhaseValue({PhaseKind::Mie, 0.0f}, float(std::cos(MieDeg(deg)))); }

// Test the built-in table's layout and that it integrates to 4 pi, both in
// closed form for the linear interpolant and by quadrature of PhaseValue.
TEST(MieTable, IsNormalised) {
    ASSERT_EQ(kMieCloudTable.count, mie::kCloudTableCount);
    EXPECT_FLOAT_EQ(kMieCloudTable.indexPerRadian, float((mie::kCloudTableCount - 1) / kMiePi));
    EXPECT_NEAR(mie::LinearTableNorm(MieCloudValues()), 1.0, 1e-6);
    // PhaseValue samples through float acos, so the quadrature sees the table to ~1e-4.
    EXPECT_NEAR(MieSphereAverage(
                    [](double t) {
                        return double(PhaseValue({PhaseKind::Mie, 0.0f}, float(std::cos(t))));
                    },
                    400000),
                1.0, 2e-4);
    // The renormalisation was small: the Mie average is normalised by construction.
    EXPECT_NEAR(mie::kCloudTableInfo.normBefore, 1.0, 0.005);
    for (float v : MieCloudValues()) {
        EXPECT_TRUE(std::isfinite(v));
        EXPECT_GT(v, 0.0f);
    }
}

// Test the features of a cloud's phase function: a strong forward peak, a fog
// bow near 140 degrees, a glory at 180, and g near 0.86.
TEST(MieTable, CloudFeatures) {
    const std::span<const float> t = MieCloudValues();
    const double step = 180.0 / double(t.size() - 1);
    // Forward peak: hundreds to thousands, and the largest value.
    EXPECT_GT(t[0], 1000.0f);
    EXPECT_LT(t[0], 20000.0f);
    EXPECT_EQ(*std::max_element(t.begin(), t.end()), t[0]);
    // Fog bow: the largest value in [120, 160] degrees is a local maximum inside (135, 145).
    const size_t lo = size_t(std::lround(120 / step)), hi = size_t(std::lround(160 / step));
    const size_t bow = size_t(std::max_element(t.begin() + lo, t.begin() + hi) - t.begin());
    const double bowDeg = double(bow) * step;
    EXPECT_GT(bowDeg, 135.0);
    EXPECT_LT(bowDeg, 145.0);
    EXPECT_GT(t[bow], 2.0f * t[size_t(std::lround(120 / step))]);
    RecordProperty("fog_bow_degrees", std::to_string(bowDeg));
    // Glory: rising toward 180 degrees, well above the side scattering at 170.
    EXPECT_GT(MieTableAt(180), 3.0 * MieTableAt(170));
    EXPECT_GT(MieTableAt(180), MieTableAt(179));
    // Asymmetry parameter: the generator's (exact) and the table's own mean cosine.
    EXPECT_GT(mie::kCloudTableInfo.g, 0.85);
    EXPECT_LT(mie::kCloudTableInfo.g, 0.87);
    const double tableG =
        MieSphereAverage([](double th) { return MieTableAt(th * 180 / kMiePi) * std::cos(th); }, 400000);
    EXPECT_NEAR(tableG, mie::kCloudTableInfo.g, 2e-3);
}

// The exact (unnormalised-table) P^ of the cloud distribution at angles in degrees.
std::vector<double> ExactMieCloudPhase(const std::vector<double>& degrees, uint32_t radii = 0) {
    mie::Distribution d = mie::CloudDistribution();
    if (radii) d.radii = radii;
    std::vector<double> mu;
    for (double a : degrees) mu.push_back(std::cos(MieDeg(a)));
    return mie::AverageOverDistribution(d, mu, 2).phase;
}

// Test that the built table is what core/math/Mie.cpp computes (at the nodes, up to float rounding and the
// recorded renormalisation).
TEST(MieTable, EqualsRecomputationAtNodes) {
    std::vector<double> degrees;
    for (double a = 0; a <= 180; a += 10) degrees.push_back(a);
    const std::vector<double> exact = ExactMieCloudPhase(degrees);
    const double step = 180.0 / double(mie::kCloudTableCount - 1);
    for (size_t k = 0; k < degrees.size(); ++k) {
        const double v = kMieCloudTable.values[size_t(std::lround(degrees[k] / step))];
        EXPECT_NEAR(v, exact[k] / mie::kCloudTableInfo.normBefore, 2e-7 * v) << degrees[k];
    }
}

// Test that the quadrature over radii has converged: doubling the nodes changes P^ by < 1 %.
TEST(MieTable, RadiusQuadratureConverged) {
    std::vector<double> degrees;
    for (double a = 0; a <= 180; a += 5) degrees.push_back(a);
    const uint32_t radii = mie::CloudDistribution().radii;
    const std::vector<double> a = ExactMieCloudPhase(degrees, radii), b = ExactMieCloudPhase(degrees, 2 * radii);
    double worst = 0;
    for (size_t k = 0; k < degrees.size(); ++k) worst = std::max(worst, std::fabs(a[k] / b[k] - 1));
    EXPECT_LT(worst, 0.01);
    RecordProperty("doubling_max_relative_change", std::to_string(worst));
}

// Test that linear interpolation of the table is within 1.5 % of the exact
// phase function at interval midpoints: every midpoint where the curvature is
// largest (the forward peak, the glory), every tenth elsewhere.
TEST(MieTable, MidpointInterpolationError) {
    const double step = 180.0 / double(mie::kCloudTableCount - 1);
    std::vector<double> degrees;
    for (uint32_t i = 0; i + 1 < mie::kCloudTableCount; ++i) {
        const double mid = (i + 0.5) * step;
        if (mid < 5 || mid > 175 || i % 10 == 0) degrees.push_back(mid);
    }
    const std::vector<double> exact = ExactMieCloudPhase(degrees);
    double worst = 0, worstDeg = 0;
    for (size_t k = 0; k < degrees.size(); ++k) {
        const double e = std::fabs(MieTableAt(degrees[k]) / (exact[k] / mie::kCloudTableInfo.normBefore) - 1);
        if (e > worst) worst = e, worstDeg = degrees[k];
    }
    EXPECT_LT(worst, 0.015) << "at " << worstDeg << " degrees";
    RecordProperty("midpoint_max_relative_error", std::to_string(worst) + " at " + std::to_string(worstDeg));
}

}  // namespace
}  // namespace cb
