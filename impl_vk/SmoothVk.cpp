// Stage `smooth` (SPEC 4) on Vulkan: smooth.comp in three separable passes.
// A share [k0, k1) (SPEC 13) runs the x and y passes over its slices and the
// radius's halo of slices on either side (the z pass reads them), and the z pass
// over its own slices only.
#include <algorithm>

#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) {
    if (radius < 0 || radius > 2) return MakeError("vk: smooth radius must be 0, 1 or 2");
    const Extent3 e = cld.Extent();
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const uint32_t r = uint32_t(radius);
    const uint32_t halo0 = k0 > r ? k0 - r : 0, halo1 = std::min(e.nz, k1 + r);
    auto pipeline = mContext->GetPipeline("smooth", 4, true);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto sumX = Scratch(VkScratch::SmoothSumX, e.Count() * 4);
    if (!sumX) return std::unexpected(sumX.error());
    auto sumXY = Scratch(VkScratch::SmoothSumXY, e.Count() * 4);
    if (!sumXY) return std::unexpected(sumXY.error());
    struct {
        uint32_t nx, ny, nz, words;
        int32_t radius;
        float invW;
        uint32_t pass, first, end;  // voxels
    } push{e.nx, e.ny, e.nz, (e.nx + 31) / 32, radius, 1.0f / float(SmoothNormaliser(radius)), 0, 0, 0};
    const DeviceBuffer* buffers[] = {&Dev(cld), *sumX, *sumXY, &Dev(q)};
    return Record("smooth", [&](VulkanContext::Recorder& rec) {
        for (push.pass = 0; push.pass < 3; ++push.pass) {
            if (push.pass > 0) rec.Barrier();
            push.first = e.nx * e.ny * (push.pass < 2 ? halo0 : k0);
            push.end = e.nx * e.ny * (push.pass < 2 ? halo1 : k1);
            rec.DispatchRange(**pipeline, buffers, &push, sizeof push, push.first, push.end);
        }
    });
}

}  // namespace cb::vk
