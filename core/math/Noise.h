// The algorithm of stage `noise` (SPEC 10a): improved Perlin, Gustavson's 3-D
// simplex and Worley noise, each periodic on an integer lattice period, fBm and
// turbulence over them, and Olajos's forming (height distribution, Gaussian
// towers, threshold) with Wang's coverage and density modulation.
//
// The per-sample functions are plain scalar code over a 256-byte permutation
// table, with no containers, so the GLSL ports can twin them line
// by line. The lattice noises are templates over the scalar type only so that
// the tests can evaluate the same formula in double (derivative checks); the
// stage itself runs them in float. Decisions SPEC leaves open are recorded in
// docs/pipeline.md, section "Noise".
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/math/Grid.h"
#include "core/math/NoiseSettings.h"
#include "core/math/Random.h"
#include "core/math/Shading.h"

namespace cb::noise {

// Lattice cells per period along each axis (> 0). The noise at p and at
// p + period_a e_a is the same.
struct Period {
    int32_t x = 1, y = 1, z = 1;
};

using Permutation = std::array<uint8_t, 256>;

// 0..255 shuffled by Fisher-Yates, drawing from Pcg32(seed) (core/math/Random.h).
Permutation MakePermutation(uint32_t seed);

// i mod n in [0, n) for any sign of i (n > 0). The stage's coordinates lie in
// [0, 2n), so the common cases skip the division.
inline int32_t WrapIndex(int32_t i, int32_t n) {
    if (uint32_t(i) < uint32_t(n)) return i;
    if (i >= n && i - n < n) return i - n;
    const int32_t r = i % n;
    return r < 0 ? r + n : r;
}

// The permutation hash of a lattice point: perm[perm[perm[a] + b] + c], indices mod 256.
inline uint32_t LatticeHash(const uint8_t* perm, int32_t a, int32_t b, int32_t c) {
    return perm[(uint32_t(perm[(uint32_t(perm[uint32_t(a) & 255u]) + uint32_t(b)) & 255u]) + uint32_t(c)) & 255u];
}

// Perlin's quintic fade 6t^5 - 15t^4 + 10t^3: 0 and 1 at the ends with zero first and second derivatives.
template <typename Real>
constexpr Real Fade(Real t) {
    return t * t * t * (t * (t * Real(6) - Real(15)) + Real(10));
}

template <typename Real>
constexpr Real Lerp(Real t, Real a, Real b) {
    return a + t * (b - a);
}

// Improved Perlin's gradient dot product: the 12 cube-edge midpoints (+-1, +-1, 0)
// and permutations, padded to 16 by repeating (1,1,0), (-1,1,0), (0,-1,1),
// (0,-1,-1) as in Perlin's 2002 reference code.
// Written as a table (branch-free); entry h is the gradient of Perlin's
// `h < 8 ? x : y` / `h < 4 ? y : h == 12 || h == 14 ? x : z` selection.
template <typename Real>
[[gnu::always_inline]] inline Real PerlinGradient(uint32_t hash, Real x, Real y, Real z) {
    static constexpr int8_t kGrad[16][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                            {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1},
                                            {1, 1, 0},  {0, -1, 1},  {-1, 1, 0}, {0, -1, -1}};
    const int8_t* g = kGrad[hash & 15u];
    return Real(g[0]) * x + Real(g[1]) * y + Real(g[2]) * z;
}

// Improved Perlin noise (Perlin 2002), periodic with `period`. Zero at every
// lattice point; C2 (the quintic fade); |n| <= 2 provably (a convex blend of
// g.d with |g.d| <= 2), within [-0.997, 0.997] measured over 5e6 points.
template <typename Real>
Real Perlin(const uint8_t* perm, Real x, Real y, Real z, Period period);

// The lattice index `floor` of a coordinate wrapped to the period, and the next one, wrapped.
struct WrappedCell {
    int32_t lo, hi;
};
inline WrappedCell WrapCell(int32_t floor, int32_t period) {
    const int32_t lo = WrapIndex(floor, period);
    return {lo, lo + 1 == period ? 0 : lo + 1};
}

// The hashes of a Perlin cell's eight corners, in the order 000, 100, 010, 110, 001, 101, 011, 111 (x fastest).
inline void PerlinCornerHashes(const uint8_t* perm, WrappedCell X, WrappedCell Y, WrappedCell Z, uint32_t h[8]) {
    h[0] = LatticeHash(perm, X.lo, Y.lo, Z.lo), h[1] = LatticeHash(perm, X.hi, Y.lo, Z.lo);
    h[2] = LatticeHash(perm, X.lo, Y.hi, Z.lo), h[3] = LatticeHash(perm, X.hi, Y.hi, Z.lo);
    h[4] = LatticeHash(perm, X.lo, Y.lo, Z.hi), h[5] = LatticeHash(perm, X.hi, Y.lo, Z.hi);
    h[6] = LatticeHash(perm, X.lo, Y.hi, Z.hi), h[7] = LatticeHash(perm, X.hi, Y.hi, Z.hi);
}

// Perlin's blend of the corner gradients at the offset (x, y, z) in [0, 1)^3 inside the cell.
template <typename Real>
[[gnu::always_inline]] inline Real PerlinBlend(const uint32_t h[8], Real x, Real y, Real z) {
    const Real u = Fade(x), v = Fade(y), w = Fade(z);
    const Real one = Real(1);
    const Real n000 = PerlinGradient(h[0], x, y, z);
    const Real n100 = PerlinGradient(h[1], x - one, y, z);
    const Real n010 = PerlinGradient(h[2], x, y - one, z);
    const Real n110 = PerlinGradient(h[3], x - one, y - one, z);
    const Real n001 = PerlinGradient(h[4], x, y, z - one);
    const Real n101 = PerlinGradient(h[5], x - one, y, z - one);
    const Real n011 = PerlinGradient(h[6], x, y - one, z - one);
    const Real n111 = PerlinGradient(h[7], x - one, y - one, z - one);
    return Lerp(w, Lerp(v, Lerp(u, n000, n100), Lerp(u, n010, n110)),
                Lerp(v, Lerp(u, n001, n101), Lerp(u, n011, n111)));
}

template <typename Real>
Real Perlin(const uint8_t* perm, Real x, Real y, Real z, Period period) {
    const Real fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    uint32_t h[8];
    PerlinCornerHashes(perm, WrapCell(int32_t(fx), period.x), WrapCell(int32_t(fy), period.y),
                       WrapCell(int32_t(fz), period.z), h);
    return PerlinBlend(h, x - fx, y - fy, z - fz);
}

// Gustavson's 12 gradients of "Simplex noise demystified" (2005), indexed by hash mod 12.
template <typename Real>
Real SimplexGradient(uint32_t hash, Real x, Real y, Real z) {
    static constexpr int8_t kGrad[12][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                            {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1}};
    const int8_t* g = kGrad[hash % 12u];
    return Real(g[0]) * x + Real(g[1]) * y + Real(g[2]) * z;
}

// The hash of simplex lattice point (a, b, c) (skewed coordinates) on a
// periodic domain. Its Cartesian position times 6 is (5a-b-c, 5b-a-c, 5c-a-b);
// that is reduced modulo 6 * period per axis and mapped back to skewed
// coordinates, a = (4u + v + w) / 18. Translating by period_x e_x maps the
// simplex lattice onto itself iff period_x is a multiple of 3, so for such
// periods the reduced point is again a lattice point and the hash (hence the
// noise) is periodic in x, y and z (docs/pipeline.md, "Noise").
inline uint32_t SimplexLatticeHash(const uint8_t* perm, int32_t a, int32_t b, int32_t c, Period period) {
    const int32_t u = WrapIndex(5 * a - b - c, 6 * period.x);
    const int32_t v = WrapIndex(5 * b - a - c, 6 * period.y);
    const int32_t w = WrapIndex(5 * c - a - b, 6 * period.z);
    return LatticeHash(perm, (4 * u + v + w) / 18, (4 * v + u + w) / 18, (4 * w + u + v) / 18);
}

// Gustavson's 3-D simplex noise (skew F3 = 1/3, unskew G3 = 1/6, kernel
// (0.6 - r^2)^4, factor 32), periodic with `period` when every period is a
// multiple of 3. Zero at every lattice point. With the radius 0.6 the kernel
// reaches past the simplex's own corners, so the noise has small
// discontinuities (not claimed smooth; where two simplices tie, the value
// itself may jump by a few 1e-3); values stay within [-0.978, 0.978] measured
// over 5e6 points (tests/NoiseTest.cpp).
template <typename Real>
Real Simplex(const uint8_t* perm, Real x, Real y, Real z, Period period) {
    const Real F3 = Real(1) / Real(3), G3 = Real(1) / Real(6);
    const Real s = (x + y + z) * F3;
    const Real fi = std::floor(x + s), fj = std::floor(y + s), fk = std::floor(z + s);
    const Real t = (fi + fj + fk) * G3;
    const Real x0 = x - (fi - t), y0 = y - (fj - t), z0 = z - (fk - t);
    int32_t i1, j1, k1, i2, j2, k2;  // offsets of the second and third corner, by the rank order of x0, y0, z0
    if (x0 >= y0) {
        if (y0 >= z0) {
            i1 = 1, j1 = 0, k1 = 0, i2 = 1, j2 = 1, k2 = 0;
        } else if (x0 >= z0) {
            i1 = 1, j1 = 0, k1 = 0, i2 = 1, j2 = 0, k2 = 1;
        } else {
            i1 = 0, j1 = 0, k1 = 1, i2 = 1, j2 = 0, k2 = 1;
        }
    } else {
        if (y0 < z0) {
            i1 = 0, j1 = 0, k1 = 1, i2 = 0, j2 = 1, k2 = 1;
        } else if (x0 < z0) {
            i1 = 0, j1 = 1, k1 = 0, i2 = 0, j2 = 1, k2 = 1;
        } else {
            i1 = 0, j1 = 1, k1 = 0, i2 = 1, j2 = 1, k2 = 0;
        }
    }
    const Real x1 = x0 - Real(i1) + G3, y1 = y0 - Real(j1) + G3, z1 = z0 - Real(k1) + G3;
    const Real x2 = x0 - Real(i2) + Real(2) * G3, y2 = y0 - Real(j2) + Real(2) * G3, z2 = z0 - Real(k2) + Real(2) * G3;
    const Real x3 = x0 - Real(1) + Real(3) * G3, y3 = y0 - Real(1) + Real(3) * G3, z3 = z0 - Real(1) + Real(3) * G3;
    const int32_t a = int32_t(fi), b = int32_t(fj), c = int32_t(fk);
    auto corner = [&](int32_t da, int32_t db, int32_t dc, Real cx, Real cy, Real cz) {
        const Real r = Real(0.6) - cx * cx - cy * cy - cz * cz;
        if (r < Real(0)) return Real(0);
        const Real r2 = r * r;
        return r2 * r2 * SimplexGradient(SimplexLatticeHash(perm, a + da, b + db, c + dc, period), cx, cy, cz);
    };
    const Real n = corner(0, 0, 0, x0, y0, z0) + corner(i1, j1, k1, x1, y1, z1) + corner(i2, j2, k2, x2, y2, z2) +
                   corner(1, 1, 1, x3, y3, z3);
    return Real(32) * n;
}

// The feature point of Worley cell (cx, cy, cz) (already wrapped to the
// period) as an offset in [0, 1)^3 from the cell's corner: three lowbias32
// draws from key = lowbias32(cx + lowbias32(cy + lowbias32(cz + lowbias32(seed)))).
inline std::array<float, 3> WorleyFeature(uint32_t seed, int32_t cx, int32_t cy, int32_t cz) {
    const uint32_t key = LowBias32(uint32_t(cx) + LowBias32(uint32_t(cy) + LowBias32(uint32_t(cz) + LowBias32(seed))));
    constexpr float kScale = 1.0f / 16777216.0f;
    return {float(LowBias32(key) >> 8) * kScale, float(LowBias32(key + 1u) >> 8) * kScale,
            float(LowBias32(key + 2u) >> 8) * kScale};
}

// Worley (cellular) noise: 1 - (distance to the nearest feature point) / sqrt(3)
// over the 27 cells around p, clamped to [0, 1]. Periodic with `period`.
float Worley(uint32_t seed, float x, float y, float z, Period period);

// The basis an fBm sums, with what it needs: a permutation table (Perlin,
// simplex) and a seed (Worley).
struct Lattice {
    NoiseBasis basis = NoiseBasis::Perlin;
    const uint8_t* perm = nullptr;
    uint32_t seed = 0;
};

inline float Basis(const Lattice& lattice, float x, float y, float z, Period period) {
    switch (lattice.basis) {
        case NoiseBasis::Perlin:
            return Perlin(lattice.perm, x, y, z, period);
        case NoiseBasis::Simplex:
            return Simplex(lattice.perm, x, y, z, period);
        case NoiseBasis::Worley:
            return Worley(lattice.seed, x, y, z, period);
    }
    return 0.0f;
}

// fBm: sum_o gain^o noise(lacunarity^o p) with the period of octave o being
// period * lacunarity^o; turbulence sums |noise|.
float Fbm(const Lattice& lattice, const FbmSettings& fbm, float x, float y, float z, Period period);

// sum_o gain^o: the largest |fBm| of a basis within [-1, 1].
float FbmNorm(const FbmSettings& fbm);

// fBm mapped to [0, 1]: f / norm for Worley and turbulence (non-negative),
// 0.5 + 0.5 f / norm for the signed bases; clamped. Fbm01FromSum maps an fBm
// sum already formed (the CPU stage forms Perlin's row by row).
float Fbm01FromSum(NoiseBasis basis, const FbmSettings& fbm, float sum);
float Fbm01(const Lattice& lattice, const FbmSettings& fbm, float x, float y, float z, Period period);

// x clamped to [0, 1] (inline compares; the inputs are finite).
inline float Clamp01(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }

// Olajos's height distribution HD(h) = (1 - e^{-a h}) e^{-b h}, h in [0, 1].
inline float HeightDistribution(float h, float a, float b) { return (1.0f - std::exp(-a * h)) * std::exp(-b * h); }

// Threshold q = clamp((v - c) / (1 - c), 0, 1), c in [0, 1): c -> 0, 1 -> 1.
inline float Threshold(float v, float c) { return Clamp01((v - c) / (1.0f - c)); }

// Schneider's erosion by detail noise d in [0, 1] with strength s in [0, 1):
// remap(v, s d, 1, 0, 1) = (v - s d) / (1 - s d).
inline float Erode(float v, float d, float strength) {
    const float e = strength * d;
    return (v - e) / (1.0f - e);
}

// A tower with its constants in float: centre (voxels) and 1 / sigma^2.
struct TowerF {
    float cx, cy, cz, ix, iy, iz, amplitude;
};

// Sum of Gaussian towers at (x, y, z) in voxels. x and y are periodic on the
// grid (nx, ny): each tower counts at its nearest periodic image, so a tower
// near an edge continues across it (seamless when 3 sigma < n/2).
inline float TowerSum(const TowerF* towers, size_t count, float x, float y, float z, float nx, float ny) {
    float sum = 0.0f;
    for (size_t n = 0; n < count; ++n) {
        const TowerF& t = towers[n];
        float dx = x - t.cx, dy = y - t.cy;
        dx -= nx * std::round(dx / nx);
        dy -= ny * std::round(dy / ny);
        const float dz = z - t.cz;
        sum += t.amplitude * std::exp(-0.5f * (dx * dx * t.ix + dy * dy * t.iy + dz * dz * t.iz));
    }
    return sum;
}

// The time coordinate of one step: offsets, already reduced modulo their
// periods in double on the host so the per-sample path adds small floats.
struct StepOffsets {
    float base[3] = {0, 0, 0};    // lattice cells of octave 0
    float detail[3] = {0, 0, 0};  // detail voxels
    float map[2] = {0, 0};        // lattice cells of the weather map
};

// Everything a scene's noise needs that does not change per step, made once:
// permutation tables, tower constants, the detail volume.
class NoiseForm {
  public:
    NoiseForm(const NoiseSettings& settings, Extent3 grid);

    const NoiseSettings& Settings() const { return mSettings; }
    const Extent3& Grid() const { return mGrid; }
    const Permutation& BasePermutation() const { return mBasePerm; }
    const std::vector<float>& DetailVolume() const { return mDetail; }  // size^3, x fastest; empty without detail

    // The offsets of step `step` (drift * step, reduced modulo the periods).
    StepOffsets Offsets(uint32_t step) const;

    Lattice BaseLattice() const { return {mSettings.fbm.basis, mBasePerm.data(), mSettings.seed}; }
    Period BasePeriod() const;
    // Lattice coordinates of octave 0 at voxel (i, j, k)'s centre (i may be nx: the next period's first voxel).
    void BaseCoordinates(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k, float p[3]) const;

    // The weather map m = max(0, 2 f - 1) in [0, 1] at column (i, j), f the map's fBm in [0, 1] (coverage).
    float Map(const StepOffsets& o, uint32_t i, uint32_t j) const;
    // The detail noise in [0, 1] at voxel (i, j, k): trilinear in the tiled detail volume.
    float Detail(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k) const;
    // The tower sum at voxel (i, j, k)'s centre.
    float Towers(uint32_t i, uint32_t j, uint32_t k) const;
    // HD at slice k's relative height (k + 0.5) / nz.
    float Height(uint32_t k) const;

    // q at voxel (i, j, k) given the base fBm in [0, 1] there and the column's map value:
    // v = base HD + towers, eroded by the detail, then thresholded or coverage-modulated.
    float Form(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k, float base01, float map) const;
    // q at voxel (i, j, k), everything included (the reference the stage must equal).
    float Q(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k) const;

  private:
    NoiseSettings mSettings;
    Extent3 mGrid;
    Permutation mBasePerm, mDetailPerm, mMapPerm;
    std::vector<TowerF> mTowers;
    std::vector<float> mDetail;
    float mScale[3];     // frequency / n per axis
    float mMapScale[2];  // map frequency / n
};

// The per-voxel steps, inline so that each SIMD target of the CPU backend
// compiles them as its own code (impl_cpu/NoiseCpu.cpp).
inline float NoiseForm::Detail(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k) const {
    const int32_t s = int32_t(mSettings.detail.size);
    const float p[3] = {float(i) + o.detail[0], float(j) + o.detail[1], float(k) + o.detail[2]};
    int32_t i0[3], i1[3];
    float t[3];
    for (int a = 0; a < 3; ++a) {
        const float f = std::floor(p[a]);
        t[a] = p[a] - f;
        i0[a] = WrapIndex(int32_t(f), s);
        i1[a] = i0[a] + 1 == s ? 0 : i0[a] + 1;
    }
    auto at = [&](int32_t a, int32_t b, int32_t c) {
        return mDetail[size_t(a) + size_t(s) * (size_t(b) + size_t(s) * c)];
    };
    const float c00 = Lerp(t[0], at(i0[0], i0[1], i0[2]), at(i1[0], i0[1], i0[2]));
    const float c10 = Lerp(t[0], at(i0[0], i1[1], i0[2]), at(i1[0], i1[1], i0[2]));
    const float c01 = Lerp(t[0], at(i0[0], i0[1], i1[2]), at(i1[0], i0[1], i1[2]));
    const float c11 = Lerp(t[0], at(i0[0], i1[1], i1[2]), at(i1[0], i1[1], i1[2]));
    return Lerp(t[2], Lerp(t[1], c00, c10), Lerp(t[1], c01, c11));
}

inline float NoiseForm::Towers(uint32_t i, uint32_t j, uint32_t k) const {
    return TowerSum(mTowers.data(), mTowers.size(), float(i) + 0.5f, float(j) + 0.5f, float(k) + 0.5f, float(mGrid.nx),
                    float(mGrid.ny));
}

inline float NoiseForm::Height(uint32_t k) const {
    return HeightDistribution((float(k) + 0.5f) / float(mGrid.nz), float(mSettings.heightA), float(mSettings.heightB));
}

inline float NoiseForm::Form(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k, float base01, float map) const {
    float v = base01 * Height(k) + Towers(i, j, k);
    if (mSettings.detail.enabled) v = Erode(v, Detail(o, i, j, k), float(mSettings.detail.strength));
    if (mSettings.coverage.enabled)
        return CoverageModulate(v, map, float(mSettings.coverage.coverage), float(mSettings.coverage.density));
    return Threshold(v, float(mSettings.threshold));
}

}  // namespace cb::noise
