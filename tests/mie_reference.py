#!/usr/bin/python3
"""Independent Lorenz-Mie values for tests/MieTest.cpp.

Not the Bohren-Huffman recurrences of core/math/Mie.cpp: a_n and b_n from their
defining formulas (Bohren & Huffman 1983, eq. 4.53) with scipy's spherical
Bessel functions j_n, y_n of real and complex argument, and the angular
functions from numpy's Legendre polynomials (pi_n = P_n'(mu),
tau_n = mu P_n'(mu) - (1 - mu^2) P_n''(mu)), and the efficiencies and g from
S1, S2 (optical theorem, quadrature over the sphere) instead of the series. Accurate for the moderate size
parameters below (x <= 30), where the direct formulas do not lose precision.

Run: /usr/bin/python3 tests/mie_reference.py   (prints the C++ table rows)
"""
import numpy as np
from numpy.polynomial import legendre as L
from scipy.special import spherical_jn, spherical_yn


def coefficients(x, m):
    nstop = int(x + 4 * x ** (1 / 3) + 2)
    n = np.arange(1, nstop + 1)
    mx = m * x
    jx, jpx = spherical_jn(n, x), spherical_jn(n, x, derivative=True)
    yx, ypx = spherical_yn(n, x), spherical_yn(n, x, derivative=True)
    jm, jpm = spherical_jn(n, mx), spherical_jn(n, mx, derivative=True)
    psi_x, dpsi_x = x * jx, jx + x * jpx            # psi(z) = z j(z)
    xi_x, dxi_x = x * (jx + 1j * yx), (jx + 1j * yx) + x * (jpx + 1j * ypx)
    psi_m, dpsi_m = mx * jm, jm + mx * jpm
    a = (m * psi_m * dpsi_x - psi_x * dpsi_m) / (m * psi_m * dxi_x - xi_x * dpsi_m)
    b = (psi_m * dpsi_x - m * psi_x * dpsi_m) / (psi_m * dxi_x - m * xi_x * dpsi_m)
    return n, a, b


def amplitudes(x, m, mu):
    """S1, S2 at the cosines mu (array)."""
    n, a, b = coefficients(x, m)
    mu = np.asarray(mu, dtype=float)
    s1 = np.zeros(mu.shape, complex)
    s2 = np.zeros(mu.shape, complex)
    for k, nn in enumerate(n):
        c = np.zeros(nn + 1)
        c[nn] = 1
        d1, d2 = L.legval(mu, L.legder(c, 1)), L.legval(mu, L.legder(c, 2))
        pi_n, tau_n = d1, mu * d1 - (1 - mu * mu) * d2
        f = (2 * nn + 1) / (nn * (nn + 1))
        s1 += f * (a[k] * pi_n + b[k] * tau_n)
        s2 += f * (a[k] * tau_n + b[k] * pi_n)
    return s1, s2


def efficiencies(x, m):
    """From S1, S2 alone: Q_ext by the optical theorem, Q_sca and g by
    Gauss-Legendre quadrature of |S1|^2 + |S2|^2 (a polynomial in mu of degree
    2 N_stop, which 400 nodes integrate exactly), Q_back from S1(180)."""
    s1, _ = amplitudes(x, m, [1.0, -1.0])
    qext = 4 / x**2 * s1[0].real
    qback = 4 * abs(s1[1]) ** 2 / x**2
    mu, w = L.leggauss(400)
    t1, t2 = amplitudes(x, m, mu)
    i = abs(t1) ** 2 + abs(t2) ** 2
    qsca = np.sum(w * i) / x**2
    g = np.sum(w * i * mu) / np.sum(w * i)
    return qext, qsca, qback, g


def phase(x, m, theta_deg):
    qsca = efficiencies(x, m)[1]
    s1, s2 = amplitudes(x, m, np.cos(np.radians(theta_deg)))
    return 2 * (abs(s1) ** 2 + abs(s2) ** 2) / (x * x * qsca)


CASES = [(0.5, 1.33), (1.0, 1.33), (10.0, 1.33), (30.0, 1.33), (3.0, 1.55), (5.0, 1.5 + 0.1j), (10.0, 1.33 + 0.05j)]
ANGLES = [0.0, 30.0, 90.0, 140.0, 180.0]

if __name__ == "__main__":
    for x, m in CASES:
        m = complex(m)
        qext, qsca, qback, g = efficiencies(x, m)
        p = phase(x, m, np.array(ANGLES))
        print("    {%g, {%g, %g}, %.9g, %.9g, %.9g, %.9g, {%s}}," % (
            x, m.real, m.imag, qext, qsca, qback, g, ", ".join("%.9g" % v for v in p)))
