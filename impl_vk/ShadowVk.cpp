// Stage `shadow` (SPEC 7) on Vulkan: shadow.comp, one invocation per column.
#include "impl_vk/BackendVk.h"
#include "impl_vk/PushBlocks.h"

namespace cb::vk {

Status BackendVk::Shadow(const ShadowParams& params, const Buffer& columnSum, Buffer& G) {
    const Extent3 e = columnSum.Extent();
    auto pipeline = mContext->GetPipeline("shadow", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    const ShadowLookup l = MakeShadowLookup(params.sun, e.nx, e.ny, params.nz, params.sigma, params.voxelSize);
    ShadowPush push{e.nx,
                    e.ny,
                    l.baseX,
                    l.baseY,
                    l.fx,
                    l.fy,
                    uint32_t(params.form),
                    l.opticalDepthPerD,
                    params.kappa,
                    l.noSun ? 1u : 0u,
                    params.coverage,
                    params.densityFactor};
    const DeviceBuffer* buffers[] = {&Dev(columnSum), &Dev(G)};
    return Record("shadow", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, e.nx * e.ny);
    });
}

}  // namespace cb::vk
