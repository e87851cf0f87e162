// Lorenz-Mie scattering by homogeneous spheres (Bohren & Huffman, "Absorption
// and Scattering of Light by Small Particles", 1983, appendix A: BHMIE) and its
// average over a cloud droplet size distribution: the source of the Mie phase
// table of SPEC 9 (docs/pipeline.md, "Mie phase table"). Double precision
// throughout; the table itself is float32 (core/math/Shading.h PhaseTable).
//
// The table is produced at build time by tools/MieTableGen.cpp, which links
// this file alone; the library keeps it for the tests.
#pragma once

#include <complex>
#include <cstdint>
#include <span>
#include <vector>

namespace cb::mie {

// The Lorenz-Mie coefficients a_n, b_n (n = 1 .. N_stop, stored at [n - 1]) of
// one sphere of size parameter x = 2 pi r / lambda and relative refractive
// index m (imaginary part >= 0 for absorption, Bohren-Huffman's convention).
struct Coefficients {
    double x = 0;
    std::vector<std::complex<double>> a, b;
};

// N_stop = x + 4 x^(1/3) + 2 terms (Wiscombe's criterion, as in BHMIE); D_n by
// downward recurrence from max(N_stop, |m x|) + 15, psi_n and xi_n upward.
// x > 0.
Coefficients ComputeCoefficients(double x, std::complex<double> m);

// Efficiencies and the asymmetry parameter g = <cos theta> of one sphere.
struct Efficiencies {
    double qExt = 0, qSca = 0, qBack = 0, g = 0;
};
Efficiencies ComputeEfficiencies(const Coefficients& c);

// The amplitude functions S1, S2 at the scattering angles whose cosines are
// given (any order, each in [-1, 1]), by the upward recurrences of pi_n, tau_n.
struct Amplitudes {
    std::complex<double> s1, s2;
};
std::vector<Amplitudes> ComputeAmplitudes(const Coefficients& c, std::span<const double> cosTheta);

// P^ = 4 pi p(theta) of one sphere: 2 (|S1|^2 + |S2|^2) / (x^2 Q_sca), so that
// its average over the sphere is 1 (isotropic scattering gives 1, SPEC 9).
std::vector<double> SpherePhase(const Coefficients& c, std::span<const double> cosTheta);

// A droplet size distribution: Hansen's standard gamma (J. Atmos. Sci. 28, 1971),
// n(r) ~ r^((1 - 3 v_eff) / v_eff) exp(-r / (r_eff v_eff)), whose effective
// radius <r^3>/<r^2> is r_eff and effective variance v_eff (0 < v_eff < 1/3).
// Water at one wavelength. Lengths in micrometres.
struct Distribution {
    double rEff = 10.0;  // cumulus (Hansen & Travis 1974; Olajos's table is for cumulus too)
    double vEff = 0.1;
    double wavelength = 0.55;            // green, the middle of the visible
    std::complex<double> m{1.333, 0.0};  // water at 0.55 um (Hale & Querry 1973: k ~ 2e-9, neglected)
    double rMin = 2.0, rMax = 30.0;      // quadrature range (see CloudDistribution)
    uint32_t radii = 2048;               // quadrature nodes over [rMin, rMax] (composite Simpson, odd count used)
};

// n(r) up to a constant, for r > 0.
double SizeDensity(const Distribution& d, double r);

// The distribution's average: P^(theta) = 2 Int n |S|^2 dr / Int n x^2 Q_sca dr
// (|S|^2 = |S1|^2 + |S2|^2) at the given cosines, and the scattering-weighted
// asymmetry parameter g = Int n x^2 Q_sca g dr / Int n x^2 Q_sca dr.
// Runs on `threads` threads (>= 1) over the radii.
struct Averaged {
    std::vector<double> phase;  // P^ at each cosine
    double g = 0;
    double qSca = 0;  // scattering-weighted <Q_sca> (~2 for large drops)
};
Averaged AverageOverDistribution(const Distribution& d, std::span<const double> cosTheta, unsigned threads = 1);

// cos(theta_i) for theta_i = i pi / (count - 1), i = 0 .. count - 1, with the
// end points exactly +-1.
std::vector<double> UniformThetaCosines(uint32_t count);

// (1/2) Int_0^pi P^(theta) sin(theta) dtheta for P^ linear in theta between
// uniform nodes (values[0] at theta = 0, values.back() at pi): exact for the
// table as sampled (closed form per interval). 1 for a normalised table.
double LinearTableNorm(std::span<const float> values);
double LinearTableNorm(std::span<const double> values);

// How the built-in table (core/math/Shading.h kMieCloudTable) was made, and what it
// came to: written by tools/MieTableGen.cpp beside the table.
struct TableInfo {
    Distribution distribution;
    uint32_t count = 0;     // table entries over [0, pi]
    double g = 0;           // the distribution's asymmetry parameter (exact, not from the table)
    double qSca = 0;        // scattering-weighted <Q_sca>
    double normBefore = 0;  // LinearTableNorm of the float table before renormalisation
    double normAfter = 0;   // and after (1 within float rounding)
    double seconds = 0;     // generation wall time
    unsigned threads = 0;
};
extern const TableInfo kCloudTableInfo;

// The generator's settings: 1801 values (0.1 degree) over [0, pi], the default
// Distribution. Shared with the tests, which recompute parts of the table.
inline constexpr uint32_t kCloudTableCount = 1801;
inline Distribution CloudDistribution() {
    Distribution d;
    d.rMin = 0.2 * d.rEff;
    d.rMax = 3.0 * d.rEff;
    d.radii = 8192;
    return d;
}

}  // namespace cb::mie
