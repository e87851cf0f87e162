#include "core/math/NoiseGpu.h"

#include <bit>

namespace cb::noise {

std::vector<uint32_t> GpuData(const NoiseForm& form) {
    const NoiseSettings& s = form.Settings();
    const Extent3 e = form.Grid();
    const uint32_t n[3] = {e.nx, e.ny, e.nz};
    std::vector<uint32_t> w(kGpuHeaderWords, 0u);
    auto f = [](double v) { return std::bit_cast<uint32_t>(float(v)); };
    w[kGpuNx] = e.nx, w[kGpuNy] = e.ny, w[kGpuNz] = e.nz;
    w[kGpuBasis] = uint32_t(s.fbm.basis);
    w[kGpuOctaves] = s.fbm.octaves;
    w[kGpuGain] = f(s.fbm.gain);
    w[kGpuLacunarity] = s.fbm.lacunarity;
    w[kGpuTurbulence] = s.fbm.turbulence ? 1u : 0u;
    // The same float constants as NoiseForm's: frequency / n rounded once.
    for (int a = 0; a < 3; ++a) w[kGpuScale + a] = f(double(s.frequency[a]) / double(n[a]));
    for (int a = 0; a < 3; ++a) w[kGpuPeriod + a] = s.frequency[a];
    w[kGpuDetailOn] = s.detail.enabled ? 1u : 0u;
    w[kGpuDetailSize] = s.detail.size;
    w[kGpuStrength] = f(s.detail.strength);
    w[kGpuCoverageOn] = s.coverage.enabled ? 1u : 0u;
    w[kGpuCoverage] = f(s.coverage.coverage);
    w[kGpuDensity] = f(s.coverage.density);
    w[kGpuThreshold] = f(s.threshold);
    w[kGpuMapOctaves] = s.coverage.octaves;
    w[kGpuMapGain] = f(s.coverage.gain);
    for (int a = 0; a < 2; ++a) {
        w[kGpuMapPeriod + a] = s.coverage.frequency[a];
        w[kGpuMapScale + a] = f(double(s.coverage.frequency[a]) / double(n[a]));
    }
    w[kGpuTowerCount] = uint32_t(s.towers.size());
    w[kGpuSeed] = s.seed;
    auto table = [&w](const Permutation& perm) {
        const uint32_t at = uint32_t(w.size());
        for (uint8_t p : perm) w.push_back(p);
        return at;
    };
    w[kGpuBasePerm] = table(form.BasePermutation());
    w[kGpuMapPerm] = table(MakePermutation(s.seed + 2u));  // NoiseForm's map table
    w[kGpuHeights] = uint32_t(w.size());
    for (uint32_t k = 0; k < e.nz; ++k) w.push_back(std::bit_cast<uint32_t>(form.Height(k)));
    w[kGpuTowers] = uint32_t(w.size());
    for (const NoiseTower& t : s.towers) {
        for (int a = 0; a < 3; ++a) w.push_back(f(t.center[a]));
        for (int a = 0; a < 3; ++a) w.push_back(f(1.0 / (t.sigma[a] * t.sigma[a])));
        w.push_back(f(t.amplitude));
    }
    w[kGpuDetail] = uint32_t(w.size());
    for (float d : form.DetailVolume()) w.push_back(std::bit_cast<uint32_t>(d));
    return w;
}

uint64_t GpuDataBytes(const NoiseSettings& s, const Extent3& grid) {
    const uint64_t detail = s.detail.enabled ? uint64_t(s.detail.size) * s.detail.size * s.detail.size : 0;
    return 4 * (kGpuHeaderWords + 2 * 256 + uint64_t(grid.nz) + 7 * uint64_t(s.towers.size()) + detail);
}

std::array<float, 8> GpuOffsets(const StepOffsets& o) {
    return {o.base[0], o.base[1], o.base[2], o.detail[0], o.detail[1], o.detail[2], o.map[0], o.map[1]};
}

}  // namespace cb::noise
