#include "core/math/Mie.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <thread>

namespace cb::mie {

using Complex = std::complex<double>;

Coefficients ComputeCoefficients(double x, Complex m) {
    assert(x > 0);
    Coefficients c;
    c.x = x;
    const Complex y = m * x;
    const double xStop = x + 4.0 * std::cbrt(x) + 2.0;
    const auto nStop = uint32_t(xStop);
    const auto nMax = uint32_t(std::max(xStop, std::abs(y))) + 15;
    // Logarithmic derivative D_n(mx) = psi_n'(mx)/psi_n(mx), downward from D_nMax = 0
    // (stable for any m; BH A.2).
    std::vector<Complex> D(nMax + 1, Complex(0, 0));
    for (uint32_t n = nMax; n >= 2; --n) {
        const Complex nOverY = double(n) / y;
        D[n - 1] = nOverY - 1.0 / (D[n] + nOverY);
    }
    // Riccati-Bessel psi_n(x) = x j_n(x), chi_n(x) = -x y_n(x), upward (stable for n <= N_stop).
    double psi0 = std::cos(x), psi1 = std::sin(x);
    double chi0 = -std::sin(x), chi1 = std::cos(x);
    Complex xi1(psi1, -chi1);
    c.a.resize(nStop);
    c.b.resize(nStop);
    for (uint32_t n = 1; n <= nStop; ++n) {
        const double dn = double(n);
        const double psi = (2.0 * dn - 1.0) * psi1 / x - psi0;
        const double chi = (2.0 * dn - 1.0) * chi1 / x - chi0;
        const Complex xi(psi, -chi);
        const Complex da = D[n] / m + dn / x;
        const Complex db = m * D[n] + dn / x;
        c.a[n - 1] = (da * psi - psi1) / (da * xi - xi1);
        c.b[n - 1] = (db * psi - psi1) / (db * xi - xi1);
        psi0 = psi1;
        psi1 = psi;
        chi0 = chi1;
        chi1 = chi;
        xi1 = Complex(psi1, -chi1);
    }
    return c;
}

Efficiencies ComputeEfficiencies(const Coefficients& c) {
    Efficiencies e;
    const size_t N = c.a.size();
    double ext = 0, sca = 0, asy = 0;
    Complex back(0, 0);
    for (size_t i = 0; i < N; ++i) {
        const double n = double(i + 1);
        const Complex an = c.a[i], bn = c.b[i];
        ext += (2 * n + 1) * (an + bn).real();
        sca += (2 * n + 1) * (std::norm(an) + std::norm(bn));
        back += (2 * n + 1) * ((i % 2 == 0) ? -1.0 : 1.0) * (an - bn);  // (-1)^n
        // g Q_sca x^2 / 4 = sum n(n+2)/(n+1) Re(a_n a*_{n+1} + b_n b*_{n+1}) + (2n+1)/(n(n+1)) Re(a_n b*_n)
        asy += (2 * n + 1) / (n * (n + 1)) * (an * std::conj(bn)).real();
        if (i + 1 < N) asy += n * (n + 2) / (n + 1) * (an * std::conj(c.a[i + 1]) + bn * std::conj(c.b[i + 1])).real();
    }
    const double x2 = c.x * c.x;
    e.qExt = 2.0 / x2 * ext;
    e.qSca = 2.0 / x2 * sca;
    e.qBack = std::norm(back) / x2;
    e.g = e.qSca > 0 ? 4.0 / x2 * asy / e.qSca : 0.0;
    return e;
}

std::vector<Amplitudes> ComputeAmplitudes(const Coefficients& c, std::span<const double> cosTheta) {
    std::vector<Amplitudes> out(cosTheta.size());
    const size_t N = c.a.size();
    // Per term: f_n (a_n, b_n) with f_n = (2n+1)/(n(n+1)).
    std::vector<Complex> fa(N), fb(N);
    for (size_t i = 0; i < N; ++i) {
        const double n = double(i + 1);
        const double f = (2 * n + 1) / (n * (n + 1));
        fa[i] = f * c.a[i];
        fb[i] = f * c.b[i];
    }
    for (size_t k = 0; k < cosTheta.size(); ++k) {
        const double mu = cosTheta[k];
        double pi0 = 0, pi1 = 1;  // pi_0, pi_1
        Complex s1(0, 0), s2(0, 0);
        for (size_t i = 0; i < N; ++i) {
            const double n = double(i + 1);
            const double tau = n * mu * pi1 - (n + 1) * pi0;
            s1 += fa[i] * pi1 + fb[i] * tau;
            s2 += fa[i] * tau + fb[i] * pi1;
            const double next = ((2 * n + 1) * mu * pi1 - (n + 1) * pi0) / n;
            pi0 = pi1;
            pi1 = next;
        }
        out[k] = {s1, s2};
    }
    return out;
}

std::vector<double> SpherePhase(const Coefficients& c, std::span<const double> cosTheta) {
    const double scale = 2.0 / (c.x * c.x * ComputeEfficiencies(c).qSca);
    const std::vector<Amplitudes> s = ComputeAmplitudes(c, cosTheta);
    std::vector<double> p(s.size());
    for (size_t k = 0; k < s.size(); ++k) p[k] = scale * (std::norm(s[k].s1) + std::norm(s[k].s2));
    return p;
}

double SizeDensity(const Distribution& d, double r) {
    // Scaled by r_eff so the power stays in range: (r/r_eff)^p exp(-(r - r_eff)/(r_eff v)).
    const double p = (1.0 - 3.0 * d.vEff) / d.vEff;
    const double u = r / d.rEff;
    return std::exp(p * std::log(u) - (u - 1.0) / d.vEff);
}

// Per-thread work arrays of AccumulateIntensity, one entry per angle.
struct IntensityScratch {
    std::vector<double> piPrev, piCur, plusRe, plusIm, minusRe, minusIm;
};

// One Legendre order n at every angle: advances pi_n to pi_(n+1) (pCur, pPrev)
// and adds c (pi_n + tau_n) to plus and d (pi_n - tau_n) to minus. Free of
// the containers so that GCC vectorises it.
static void AddOrder(size_t J, double n, double cr, double ci, double dr, double di, const double* __restrict mu,
                     double* __restrict pPrev, double* __restrict pCur, double* __restrict plusRe,
                     double* __restrict plusIm, double* __restrict minusRe, double* __restrict minusIm) {
    const double np1 = n + 1, tnp1 = 2 * n + 1, invN = 1.0 / n;
    for (size_t j = 0; j < J; ++j) {
        const double p = pCur[j], q = pPrev[j], mp = mu[j] * p, nq = np1 * q;
        const double tau = n * mp - nq;
        const double u = p + tau, v = p - tau;
        plusRe[j] += cr * u;
        plusIm[j] += ci * u;
        minusRe[j] += dr * v;
        minusIm[j] += di * v;
        pPrev[j] = p;
        pCur[j] = (tnp1 * mp - nq) * invN;
    }
}

// |S1|^2 + |S2|^2 at the cosines, times w, added to `sum`. The same sums as
// ComputeAmplitudes, arranged for speed: |S1|^2 + |S2|^2 = (|S+|^2 + |S-|^2)/2
// with S+- = S1 +- S2 = sum f_n (a_n +- b_n)(pi_n +- tau_n), and the angles as
// the inner loop (vectorised).
static void AccumulateIntensity(const Coefficients& c, std::span<const double> cosTheta, double w,
                                std::vector<double>& sum, IntensityScratch& s) {
    const size_t J = cosTheta.size();
    s.piPrev.assign(J, 0.0);  // pi_0
    s.piCur.assign(J, 1.0);   // pi_1
    s.plusRe.assign(J, 0.0);
    s.plusIm.assign(J, 0.0);
    s.minusRe.assign(J, 0.0);
    s.minusIm.assign(J, 0.0);
    const size_t N = c.a.size();
    for (size_t i = 0; i < N; ++i) {
        const double n = double(i + 1);
        const double f = (2 * n + 1) / (n * (n + 1));
        const std::complex<double> plus = f * (c.a[i] + c.b[i]), minus = f * (c.a[i] - c.b[i]);
        AddOrder(J, n, plus.real(), plus.imag(), minus.real(), minus.imag(), cosTheta.data(), s.piPrev.data(),
                 s.piCur.data(), s.plusRe.data(), s.plusIm.data(), s.minusRe.data(), s.minusIm.data());
    }
    const double half = 0.5 * w;
    for (size_t j = 0; j < J; ++j)
        sum[j] += half * (s.plusRe[j] * s.plusRe[j] + s.plusIm[j] * s.plusIm[j] + s.minusRe[j] * s.minusRe[j] +
                          s.minusIm[j] * s.minusIm[j]);
}

Averaged AverageOverDistribution(const Distribution& d, std::span<const double> cosTheta, unsigned threads) {
    // Composite Simpson over r with an odd node count.
    const uint32_t nodes = std::max<uint32_t>(3, d.radii | 1u);
    const double h = (d.rMax - d.rMin) / double(nodes - 1);
    const double k = 2.0 * std::numbers::pi / d.wavelength;
    threads = std::max(1u, threads);

    struct Partial {
        std::vector<double> intensity;
        double scatter = 0, scatterG = 0;
    };
    std::vector<Partial> partial(threads);
    auto work = [&](unsigned t) {
        Partial& p = partial[t];
        IntensityScratch scratch;
        p.intensity.assign(cosTheta.size(), 0.0);
        for (uint32_t i = t; i < nodes; i += threads) {
            const double r = d.rMin + h * double(i);
            const double simpson = (i == 0 || i == nodes - 1) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
            const double w = simpson * SizeDensity(d, r);
            const Coefficients c = ComputeCoefficients(k * r, d.m);
            const Efficiencies e = ComputeEfficiencies(c);
            const double cross = w * c.x * c.x * e.qSca;
            p.scatter += cross;
            p.scatterG += cross * e.g;
            AccumulateIntensity(c, cosTheta, w, p.intensity, scratch);
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work, t);
    work(0);
    for (std::thread& th : pool) th.join();

    Averaged out;
    out.phase.assign(cosTheta.size(), 0.0);
    double scatter = 0, scatterG = 0, area = 0;
    for (const Partial& p : partial) {
        for (size_t j = 0; j < cosTheta.size(); ++j) out.phase[j] += p.intensity[j];
        scatter += p.scatter;
        scatterG += p.scatterG;
    }
    for (uint32_t i = 0; i < nodes; ++i) {
        const double r = d.rMin + h * double(i);
        const double simpson = (i == 0 || i == nodes - 1) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
        area += simpson * SizeDensity(d, r) * (k * r) * (k * r);
    }
    for (double& v : out.phase) v *= 2.0 / scatter;
    out.g = scatterG / scatter;
    out.qSca = scatter / area;
    return out;
}

std::vector<double> UniformThetaCosines(uint32_t count) {
    assert(count >= 2);
    std::vector<double> mu(count);
    for (uint32_t i = 0; i < count; ++i) mu[i] = std::cos(std::numbers::pi * double(i) / double(count - 1));
    mu.front() = 1.0;
    mu.back() = -1.0;
    return mu;
}

template <typename T>
static double LinearNorm(std::span<const T> values) {
    const size_t n = values.size();
    if (n < 2) return 0.0;
    const double h = std::numbers::pi / double(n - 1);
    double sum = 0;
    for (size_t i = 0; i + 1 < n; ++i) {
        const double a = h * double(i), b = h * double(i + 1);
        const double pa = double(values[i]), pb = double(values[i + 1]);
        // Int_a^b (pa + (pb - pa)(t - a)/h) sin t dt.
        sum += pa * (std::cos(a) - std::cos(b)) + (pb - pa) / h * (std::sin(b) - std::sin(a) - h * std::cos(b));
    }
    return 0.5 * sum;
}

double LinearTableNorm(std::span<const float> values) { return LinearNorm(values); }
double LinearTableNorm(std::span<const double> values) { return LinearNorm(values); }

}  // namespace cb::mie
