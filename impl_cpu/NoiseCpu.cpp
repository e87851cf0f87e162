// Stage `noise` on the CPU (SPEC 10a): q formed from noise, by the formulas of
// core/Noise.h.
//
// Schedule: the per-scene state (permutation tables, the detail volume) is
// made once and kept in the backend; each call computes the step's offsets on
// the host, the weather map's columns when coverage is on, and then every
// voxel of q, in parallel over rows (j, k) with TBB. Each voxel is independent
// and goes through exactly NoiseForm::Q's operations, so the output equals the
// reference voxel for voxel.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {

Status BackendCpu::Noise(const NoiseParams& params, Buffer& q) {
    if (!params.settings) return MakeError("cpu: noise without settings");
    if (q.Format() != BufferFormat::F32 || !(q.Extent() == params.grid))
        return MakeError("cpu: noise: q must be an F32 volume of the grid's size");
    if (!mNoiseForm || !(mNoiseForm->Settings() == *params.settings) || !(mNoiseForm->Grid() == params.grid))
        mNoiseForm = std::make_unique<noise::NoiseForm>(*params.settings, params.grid);
    const noise::NoiseForm& form = *mNoiseForm;
    const noise::StepOffsets offsets = form.Offsets(params.step);
    const Extent3 e = params.grid;
    const bool coverage = params.settings->coverage.enabled;
    float* out = static_cast<BufferCpu&>(q).F32();

    mArena.execute([&] {
        if (coverage) {
            mNoiseMap.resize(size_t(e.nx) * e.ny);
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny), [&](const tbb::blocked_range<uint32_t>& rows) {
                for (uint32_t j = rows.begin(); j != rows.end(); ++j)
                    for (uint32_t i = 0; i < e.nx; ++i) mNoiseMap[i + size_t(e.nx) * j] = form.Map(offsets, i, j);
            });
        }
        const noise::Lattice lattice = form.BaseLattice();
        const noise::Period period = form.BasePeriod();
        const FbmSettings& fbm = params.settings->fbm;
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny * e.nz), [&](const tbb::blocked_range<uint32_t>& rows) {
            for (uint32_t row = rows.begin(); row != rows.end(); ++row) {
                const uint32_t j = row % e.ny, k = row / e.ny;
                float* o = out + size_t(e.nx) * row;
                const float* map = coverage ? mNoiseMap.data() + size_t(e.nx) * j : nullptr;
                for (uint32_t i = 0; i < e.nx; ++i) {
                    float p[3];
                    form.BaseCoordinates(offsets, i, j, k, p);
                    const float base = noise::Fbm01(lattice, fbm, p[0], p[1], p[2], period);
                    o[i] = form.Form(offsets, i, j, k, base, map ? map[i] : 0.0f);
                }
            }
        });
    });
    return {};
}

}  // namespace cb::cpu
