// Stage `shadow` on the CPU (SPEC 7): the ground's shadow from the density
// map's column sums, one bilinear lookup per ground cell toward the sun.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/ShadowCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/math/Shading.h"
#include "impl_cpu/BackendCpu.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {

Status Shadow(tbb::task_arena& arena, const ShadowParams& params, const Buffer& columnSumBuffer, Buffer& GBuffer) {
    const float* D = static_cast<const BufferCpu&>(columnSumBuffer).F32();
    float* G = static_cast<BufferCpu&>(GBuffer).F32();
    const Extent3 e = columnSumBuffer.Extent();
    const ShadowLookup l = MakeShadowLookup(params.sun, e.nx, e.ny, params.nz, params.sigma, params.voxelSize);
    if (l.noSun) {  // no sun above the horizon: no shadow (docs/pipeline.md)
        std::fill(G, G + size_t(e.nx) * e.ny, 1.0f);
        return {};
    }
    const bool beer = params.form == ShadowForm::Beer, wang = params.form == ShadowForm::Wang;
    auto tap = [&](int64_t i, int64_t j) -> float {
        return (i < 0 || j < 0 || i >= e.nx || j >= e.ny) ? 0.0f : D[size_t(i) + size_t(e.nx) * size_t(j)];
    };
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny, 8), [&](const tbb::blocked_range<uint32_t>& rows) {
            for (uint32_t j = rows.begin(); j != rows.end(); ++j)
                for (uint32_t i = 0; i < e.nx; ++i) {
                    const int64_t x = int64_t(i) + l.baseX, y = int64_t(j) + l.baseY;
                    const float d = Bilinear(tap(x, y), tap(x + 1, y), tap(x, y + 1), tap(x + 1, y + 1), l.fx, l.fy);
                    G[i + size_t(e.nx) * j] =
                        wang ? WangShadow(l.opticalDepthPerD, params.coverage, params.densityFactor, d)
                             : GroundShadow(beer, l.opticalDepthPerD, params.kappa, d);
                }
        });
    });
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(Shadow);

Status BackendCpu::Shadow(const ShadowParams& params, const Buffer& columnSumBuffer, Buffer& GBuffer) {
    return HWY_DYNAMIC_DISPATCH(Shadow)(mArena, params, columnSumBuffer, GBuffer);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
