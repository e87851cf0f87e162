// The sky light's T_sky for the vk renderers (SkyVolumeVk.h): its padded volume's bytes and dispatch, and the check
// of its input. The pass is made by the façade (BackendVk::PrepareSkyVolume, BackendVk.cpp), whose scratch it uses.
#include "impl_vk/SkyVolumeVk.h"

#include <string>

namespace cb::vk {

uint64_t SkyVolumeBytes(const Extent3& e) { return uint64_t(e.nx + 2ull) * (e.ny + 2ull) * (e.nz + 2ull) * 4u; }

Status CheckSkyInput(const Buffer* TSky, const Extent3& e, const char* stage) {
    if (!TSky || TSky->Extent() != e)
        return MakeError(std::string("vk: ") + stage + ": the sky light needs T_sky of q's size");
    return {};
}

void SkyVolumePass::Record(VulkanContext::Recorder& r) const {
    if (!pipeline) return;
    const uint32_t px = push.nx + 2, py = push.ny + 2, pz = push.nz + 2;
    r.DispatchGroups(*pipeline, buffers, &push, sizeof push, CeilDiv(px, 64u), py, pz);
}

}  // namespace cb::vk
