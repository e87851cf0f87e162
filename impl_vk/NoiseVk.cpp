// Stage `noise` (SPEC 10a) on Vulkan: noise.comp, one invocation per voxel.
// The scene's data block (core/math/NoiseGpu.h: permutation tables, HD per slice,
// towers, the detail volume) is made and uploaded once per scene and kept in
// the NoiseData slot while the settings and the grid stay the same; each call
// pushes only the step's offsets.
#include "core/math/NoiseGpu.h"
#include "impl_vk/BackendVk.h"
#include "impl_vk/NoiseVkState.h"
#include "impl_vk/PushBlocks.h"

namespace cb::vk {

uint64_t NoiseVkState::ScratchBytes(const Scene& scene) const {
    return noise::GpuDataBytes(scene.noise, scene.grid.size);
}

Status BackendVk::Noise(const NoiseParams& params, Buffer& q) {
    NoiseVkState& state = mStages.Get<NoiseVkState>();
    if (!params.settings) return MakeError("vk: noise without settings");
    if (q.Format() != BufferFormat::F32 || !(q.Extent() == params.grid))
        return MakeError("vk: noise: q must be an F32 volume of the grid's size");
    auto pipeline = mContext->GetPipeline("noise", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    if (!state.form || !(state.form->Settings() == *params.settings) || !(state.form->Grid() == params.grid)) {
        state.form.reset();
        auto form = std::make_unique<noise::NoiseForm>(*params.settings, params.grid);
        const std::vector<uint32_t> words = noise::GpuData(*form);
        auto data = Scratch(state.data, words.size() * 4);
        if (!data) return std::unexpected(data.error());
        CB_TRY(mContext->Upload(**data, std::as_bytes(std::span(words))));
        state.form = std::move(form);
    }
    const NoisePush push{noise::GpuOffsets(state.form->Offsets(params.step))};
    const DeviceBuffer* buffers[] = {&state.data.buffer, &Dev(q)};
    return Record("noise", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, uint32_t(params.grid.Count()));
    });
}

}  // namespace cb::vk
