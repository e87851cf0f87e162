// Stage `noise` on the CPU (SPEC 10a): q formed from noise, by the formulas of
// core/math/Noise.h.
//
// Schedule: the per-scene state (permutation tables, the detail volume) is
// made once and kept in the backend; each call computes the step's offsets on
// the host, the weather map's columns when coverage is on, and then every
// voxel of q, in parallel over rows (j, k) with TBB. Each voxel goes through
// exactly NoiseForm::Q's operations, so the output equals the reference voxel
// for voxel. Perlin fBm runs octave by octave along a row: y and z are the
// same for the whole row, and a cell's eight corner hashes are reused until x
// enters the next cell (at octave 0 of frequency 4 on 128 voxels, once per 32).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/NoiseCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <climits>
#include <vector>

#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/NoiseCpuState.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

// sums[i] = the Perlin fBm sum (noise::Fbm) at voxel (i, j, k) of row (j, k), for i in [0, nx).
void PerlinFbmRow(const noise::NoiseForm& form, const noise::StepOffsets& offsets, uint32_t j, uint32_t k,
                  float* sums) {
    const NoiseSettings& s = form.Settings();
    const FbmSettings& fbm = s.fbm;
    const noise::Period period = form.BasePeriod();
    const uint8_t* perm = form.BasePermutation().data();
    const uint32_t nx = form.Grid().nx;
    float p0[3];
    form.BaseCoordinates(offsets, 0, j, k, p0);  // p[1] and p[2] are the row's
    for (uint32_t i = 0; i < nx; ++i) sums[i] = 0.0f;
    float amplitude = 1.0f;
    const float gain = float(fbm.gain);
    int32_t m = 1;
    for (uint32_t o = 0; o < fbm.octaves; ++o) {
        const float fm = float(m);
        const noise::Period pm{period.x * m, period.y * m, period.z * m};
        const float y = p0[1] * fm, z = p0[2] * fm;
        const float fy = std::floor(y), fz = std::floor(z);
        const noise::WrappedCell Y = noise::WrapCell(int32_t(fy), pm.y), Z = noise::WrapCell(int32_t(fz), pm.z);
        const float yf = y - fy, zf = z - fz;
        int32_t lastX = INT32_MIN;
        uint32_t h[8];
        for (uint32_t i = 0; i < nx; ++i) {
            float p[3];
            form.BaseCoordinates(offsets, i, j, k, p);
            const float x = p[0] * fm;
            const float fx = std::floor(x);
            const int32_t X = int32_t(fx);
            if (X != lastX) {
                noise::PerlinCornerHashes(perm, noise::WrapCell(X, pm.x), Y, Z, h);
                lastX = X;
            }
            const float n = noise::PerlinBlend(h, x - fx, yf, zf);
            sums[i] += amplitude * (fbm.turbulence ? std::fabs(n) : n);
        }
        amplitude *= gain;
        m *= int32_t(fbm.lacunarity);
    }
}

}  // namespace

Status Noise(tbb::task_arena& arena, NoiseCpuState& state, const NoiseParams& params, Buffer& q) {
    if (!params.settings) return MakeError("cpu: noise without settings");
    if (q.Format() != BufferFormat::F32 || !(q.Extent() == params.grid))
        return MakeError("cpu: noise: q must be an F32 volume of the grid's size");
    if (!state.form || !(state.form->Settings() == *params.settings) || !(state.form->Grid() == params.grid))
        state.form = std::make_unique<noise::NoiseForm>(*params.settings, params.grid);
    const noise::NoiseForm& form = *state.form;
    const noise::StepOffsets offsets = form.Offsets(params.step);
    const Extent3 e = params.grid;
    const bool coverage = params.settings->coverage.enabled;
    float* out = static_cast<BufferCpu&>(q).F32();

    arena.execute([&] {
        if (coverage) {
            state.map.resize(size_t(e.nx) * e.ny);
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny), [&](const tbb::blocked_range<uint32_t>& rows) {
                for (uint32_t j = rows.begin(); j != rows.end(); ++j)
                    for (uint32_t i = 0; i < e.nx; ++i) state.map[i + size_t(e.nx) * j] = form.Map(offsets, i, j);
            });
        }
        const noise::Lattice lattice = form.BaseLattice();
        const noise::Period period = form.BasePeriod();
        const FbmSettings& fbm = params.settings->fbm;
        const bool perlinRows = fbm.basis == NoiseBasis::Perlin;
        tbb::enumerable_thread_specific<std::vector<float>> rowSums(std::vector<float>(e.nx));
        // flatten: the noise functions (core/math, compiled for the baseline
        // where they are not inlined) become this target's code.
        tbb::parallel_for(
            tbb::blocked_range<uint32_t>(0, e.ny * e.nz), [&](const tbb::blocked_range<uint32_t>& rows) __attribute__((
                                                              flatten)) {
                std::vector<float>& sums = rowSums.local();
                for (uint32_t row = rows.begin(); row != rows.end(); ++row) {
                    const uint32_t j = row % e.ny, k = row / e.ny;
                    float* o = out + size_t(e.nx) * row;
                    const float* map = coverage ? state.map.data() + size_t(e.nx) * j : nullptr;
                    if (perlinRows) PerlinFbmRow(form, offsets, j, k, sums.data());
                    for (uint32_t i = 0; i < e.nx; ++i) {
                        float base;
                        if (perlinRows) {
                            base = noise::Fbm01FromSum(fbm.basis, fbm, sums[i]);
                        } else {
                            float p[3];
                            form.BaseCoordinates(offsets, i, j, k, p);
                            base = noise::Fbm01(lattice, fbm, p[0], p[1], p[2], period);
                        }
                        o[i] = form.Form(offsets, i, j, k, base, map ? map[i] : 0.0f);
                    }
                }
            });
    });
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(Noise);

uint64_t NoiseCpuState::ScratchBytes(const Scene& scene) const {
    const NoiseSettings& n = scene.noise;
    uint64_t bytes = 0;
    if (n.detail.enabled) bytes = SaturatingAdd(bytes, 4 * uint64_t(n.detail.size) * n.detail.size * n.detail.size);
    if (n.coverage.enabled) bytes = SaturatingAdd(bytes, 4 * uint64_t(scene.grid.size.nx) * scene.grid.size.ny);
    return bytes;
}

Status BackendCpu::Noise(const NoiseParams& params, Buffer& q) {
    return HWY_DYNAMIC_DISPATCH(Noise)(mArena, mStages.Get<NoiseCpuState>(), params, q);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
