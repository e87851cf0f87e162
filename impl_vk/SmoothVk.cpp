// Stage `smooth` (SPEC 4) on Vulkan: smooth.comp in three separable passes.
#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) {
    if (slices != SliceRange{}) return MakeError("vk: smooth in shares (time-slicing) is not implemented yet");
    if (radius < 0 || radius > 2) return MakeError("vk: smooth radius must be 0, 1 or 2");
    const Extent3 e = cld.Extent();
    auto pipeline = mContext->GetPipeline("smooth", 4);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto sumX = Scratch(VkScratch::SmoothSumX, e.Count() * 4);
    if (!sumX) return std::unexpected(sumX.error());
    auto sumXY = Scratch(VkScratch::SmoothSumXY, e.Count() * 4);
    if (!sumXY) return std::unexpected(sumXY.error());
    struct {
        uint32_t nx, ny, nz, words;
        int32_t radius;
        float invW;
        uint32_t pass;
    } push{e.nx, e.ny, e.nz, (e.nx + 31) / 32, radius, 1.0f / float(SmoothNormaliser(radius)), 0};
    const DeviceBuffer* buffers[] = {&Dev(cld), *sumX, *sumXY, &Dev(q)};
    return Record("smooth", [&](VulkanContext::Recorder& r) {
        for (push.pass = 0; push.pass < 3; ++push.pass) {
            if (push.pass > 0) r.Barrier();
            r.Dispatch(**pipeline, buffers, &push, sizeof push, uint32_t(e.Count()));
        }
    });
}

}  // namespace cb::vk
