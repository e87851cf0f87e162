// Shafts of light (SPEC 18) on Vulkan: shafts.comp adds the shells' light to the image in place, the constants
// (core/math/Shafts.h ShaftsFrame) in a storage buffer.
#include "core/pipeline/ShaftsPass.h"
#include "impl_vk/BackendVk.h"

namespace cb::vk {

Status BackendVk::AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) {
    CB_TRY(CheckShaftsBuffers(frame, columnSum, image, "vk"));
    auto pipeline = mContext->GetPipeline("shafts", 3);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto block = Scratch(mShaftsFrame, sizeof frame);
    if (!block) return std::unexpected(block.error());
    CB_TRY(mContext->Upload(**block, std::as_bytes(std::span(&frame, 1))));
    const DeviceBuffer* buffers[] = {*block, &Dev(columnSum), &Dev(image)};
    return Record("shafts", [&](VulkanContext::Recorder& r) {
        r.DispatchGroups(**pipeline, buffers, nullptr, 0, CeilDiv(frame.width, 8), CeilDiv(frame.height, 8), 1);
    });
}

}  // namespace cb::vk
