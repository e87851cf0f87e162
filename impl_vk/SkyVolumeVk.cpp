// The sky light's T_sky for the vk renderers (SkyVolumeVk.h): its padded volume and the check of its input.
#include "impl_vk/SkyVolumeVk.h"

#include <string>

#include "impl_vk/BackendVk.h"

namespace cb::vk {

uint64_t SkyVolumeBytes(const Extent3& e) { return uint64_t(e.nx + 2ull) * (e.ny + 2ull) * (e.nz + 2ull) * 4u; }

Status CheckSkyInput(const Buffer* TSky, const Extent3& e, const char* stage) {
    if (!TSky || TSky->Extent() != e)
        return MakeError(std::string("vk: ") + stage + ": the sky light needs T_sky of q's size");
    return {};
}

void SkyVolumePass::Record(VulkanContext::Recorder& r) const {
    const uint32_t px = push.nx + 2, py = push.ny + 2, pz = push.nz + 2;
    r.DispatchGroups(*pipeline, buffers, &push, sizeof push, CeilDiv(px, 64u), py, pz);
}

Result<SkyVolumePass> BackendVk::PrepareSkyVolume(BufferSlot& slot, const Buffer& TSky, bool tiling) {
    const Extent3 e = TSky.Extent();
    SkyVolumePass pass;
    auto pipeline = mContext->GetPipeline("sky_volume", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto volume = Scratch(slot, SkyVolumeBytes(e));
    if (!volume) return std::unexpected(volume.error());
    pass.pipeline = *pipeline;
    pass.buffers = {&Dev(TSky), *volume};
    pass.push = {e.nx, e.ny, e.nz, tiling ? 1u : 0u};
    return pass;
}

}  // namespace cb::vk
