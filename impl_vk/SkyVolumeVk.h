// The sky light's T_sky as the vk renderers read it (read only with the sky light on, LightTerms::skyOn):
// render_march and render_layers read T_sky's padded volume, formed per call in a scratch slot of their own by
// shaders/sky_volume.comp in the layout of their (q, T) volume (march_volume.comp: border 1, or wrapped in x and
// y with tiling), bound as a storage buffer; render_splat reads T_sky at the voxel, like T.
#pragma once

#include <array>
#include <cstdint>

#include "core/pipeline/Backend.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/VulkanContext.h"

namespace cb::vk {

// Bytes of T_sky's padded volume on a grid of extent e: a float per padded voxel.
uint64_t SkyVolumeBytes(const Extent3& e);

// An error naming the backend and `stage` unless T_sky is there and of q's extent e.
Status CheckSkyInput(const Buffer* TSky, const Extent3& e, const char* stage);

// T_sky's padded volume for one renderer call (BackendVk::PrepareSkyVolume): the dispatch that forms it, recorded
// in the renderer's submit before the barrier that orders its volume before the pixels, and the buffer the renderer
// binds. Without the sky light there is no dispatch and a stand-in is bound, unread.
struct SkyVolumePass {
    Pipeline* pipeline = nullptr;                  // null: no sky light
    std::array<const DeviceBuffer*, 2> buffers{};  // T_sky, the padded volume (or the stand-in)
    SkyVolumePush push{};
    const DeviceBuffer* Volume() const { return buffers[1]; }
    void Record(VulkanContext::Recorder& r) const;  // records nothing without the sky light
};

}  // namespace cb::vk
