#include "core/math/Noise.h"

#include <algorithm>
#include <numeric>

namespace cb::noise {

Permutation MakePermutation(uint32_t seed) {
    Permutation perm;
    std::iota(perm.begin(), perm.end(), uint8_t(0));
    Pcg32 rng(seed);
    for (uint32_t n = 255; n > 0; --n) std::swap(perm[n], perm[rng.Below(n + 1)]);
    return perm;
}

float Worley(uint32_t seed, float x, float y, float z, Period period) {
    const float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    const int32_t X = int32_t(fx), Y = int32_t(fy), Z = int32_t(fz);
    x -= fx, y -= fy, z -= fz;
    float best = 3.0f;  // the own cell's point is within sqrt(3)
    for (int32_t dz = -1; dz <= 1; ++dz)
        for (int32_t dy = -1; dy <= 1; ++dy)
            for (int32_t dx = -1; dx <= 1; ++dx) {
                const std::array<float, 3> f = WorleyFeature(seed, WrapIndex(X + dx, period.x),
                                                             WrapIndex(Y + dy, period.y), WrapIndex(Z + dz, period.z));
                const float ex = float(dx) + f[0] - x, ey = float(dy) + f[1] - y, ez = float(dz) + f[2] - z;
                best = std::min(best, ex * ex + ey * ey + ez * ez);
            }
    return Clamp01(1.0f - std::sqrt(best) * 0.57735026918962576f);
}

float Fbm(const Lattice& lattice, const FbmSettings& fbm, float x, float y, float z, Period period) {
    float sum = 0.0f, amplitude = 1.0f;
    int32_t m = 1;
    const float gain = float(fbm.gain);
    for (uint32_t o = 0; o < fbm.octaves; ++o) {
        const float fm = float(m);
        const float n = Basis(lattice, x * fm, y * fm, z * fm, Period{period.x * m, period.y * m, period.z * m});
        sum += amplitude * (fbm.turbulence ? std::fabs(n) : n);
        amplitude *= gain;
        m *= int32_t(fbm.lacunarity);
    }
    return sum;
}

float FbmNorm(const FbmSettings& fbm) {
    float norm = 0.0f, amplitude = 1.0f;
    for (uint32_t o = 0; o < fbm.octaves; ++o) norm += amplitude, amplitude *= float(fbm.gain);
    return norm;
}

float Fbm01FromSum(NoiseBasis basis, const FbmSettings& fbm, float sum) {
    const float f = sum / FbmNorm(fbm);
    const bool unsignedBasis = fbm.turbulence || basis == NoiseBasis::Worley;
    return Clamp01(unsignedBasis ? f : 0.5f + 0.5f * f);
}

float Fbm01(const Lattice& lattice, const FbmSettings& fbm, float x, float y, float z, Period period) {
    return Fbm01FromSum(lattice.basis, fbm, Fbm(lattice, fbm, x, y, z, period));
}

namespace {

// a - b floor(a / b) in [0, b), in double: the host-side reduction of an offset.
double PositiveMod(double a, double b) {
    const double r = std::fmod(a, b);
    return r < 0 ? r + b : r;
}

FbmSettings MapFbm(const NoiseCoverage& c) { return {NoiseBasis::Perlin, c.octaves, c.gain, 2, false}; }

}  // namespace

NoiseForm::NoiseForm(const NoiseSettings& settings, Extent3 grid)
    : mSettings(settings),
      mGrid(grid),
      mBasePerm(MakePermutation(settings.seed)),
      mDetailPerm(MakePermutation(settings.seed + 1u)),
      mMapPerm(MakePermutation(settings.seed + 2u)) {
    const uint32_t n[3] = {grid.nx, grid.ny, grid.nz};
    for (int a = 0; a < 3; ++a) mScale[a] = float(double(settings.frequency[a]) / double(n[a]));
    for (int a = 0; a < 2; ++a) mMapScale[a] = float(double(settings.coverage.frequency[a]) / double(n[a]));
    for (const NoiseTower& t : settings.towers)
        mTowers.push_back({float(t.center[0]), float(t.center[1]), float(t.center[2]),
                           float(1.0 / (t.sigma[0] * t.sigma[0])), float(1.0 / (t.sigma[1] * t.sigma[1])),
                           float(1.0 / (t.sigma[2] * t.sigma[2])), float(t.amplitude)});
    if (settings.detail.enabled) {
        const NoiseDetail& d = settings.detail;
        const uint32_t s = d.size;
        const Lattice lattice{d.fbm.basis, mDetailPerm.data(), settings.seed + 1u};
        const int32_t f = int32_t(d.frequency);
        const float scale = float(double(f) / double(s));
        mDetail.resize(size_t(s) * s * s);
        for (uint32_t c = 0; c < s; ++c)
            for (uint32_t b = 0; b < s; ++b)
                for (uint32_t a = 0; a < s; ++a)
                    mDetail[a + size_t(s) * (b + size_t(s) * c)] =
                        Fbm01(lattice, d.fbm, (float(a) + 0.5f) * scale, (float(b) + 0.5f) * scale,
                              (float(c) + 0.5f) * scale, Period{f, f, f});
    }
}

Period NoiseForm::BasePeriod() const {
    return {int32_t(mSettings.frequency[0]), int32_t(mSettings.frequency[1]), int32_t(mSettings.frequency[2])};
}

StepOffsets NoiseForm::Offsets(uint32_t step) const {
    StepOffsets o;
    const uint32_t n[3] = {mGrid.nx, mGrid.ny, mGrid.nz};
    for (int a = 0; a < 3; ++a) {
        // The noise moves by +drift per step: sample at x - drift * step.
        const double voxels = -mSettings.drift[a] * double(step);
        const double f = mSettings.frequency[a];
        o.base[a] = float(PositiveMod(voxels * f / double(n[a]), f));
        if (mSettings.detail.enabled) o.detail[a] = float(PositiveMod(voxels, double(mSettings.detail.size)));
        if (a < 2) {
            const double fm = mSettings.coverage.frequency[a];
            o.map[a] = float(PositiveMod(voxels * fm / double(n[a]), fm));
        }
        // Rounding may land exactly on the period; the lattice wraps it anyway.
    }
    return o;
}

void NoiseForm::BaseCoordinates(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k, float p[3]) const {
    p[0] = (float(i) + 0.5f) * mScale[0] + o.base[0];
    p[1] = (float(j) + 0.5f) * mScale[1] + o.base[1];
    p[2] = (float(k) + 0.5f) * mScale[2] + o.base[2];
}

float NoiseForm::Map(const StepOffsets& o, uint32_t i, uint32_t j) const {
    const NoiseCoverage& c = mSettings.coverage;
    const Lattice lattice{NoiseBasis::Perlin, mMapPerm.data(), 0};
    const float f = Fbm01(lattice, MapFbm(c), (float(i) + 0.5f) * mMapScale[0] + o.map[0],
                          (float(j) + 0.5f) * mMapScale[1] + o.map[1], 0.5f,
                          Period{int32_t(c.frequency[0]), int32_t(c.frequency[1]), 1});
    return std::max(2.0f * f - 1.0f, 0.0f);
}

float NoiseForm::Q(const StepOffsets& o, uint32_t i, uint32_t j, uint32_t k) const {
    float p[3];
    BaseCoordinates(o, i, j, k, p);
    const float base = Fbm01(BaseLattice(), mSettings.fbm, p[0], p[1], p[2], BasePeriod());
    const float map = mSettings.coverage.enabled ? Map(o, i, j) : 0.0f;
    return Form(o, i, j, k, base, map);
}

}  // namespace cb::noise
