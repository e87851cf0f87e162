// Stage `smooth` (SPEC 4) on Vulkan: smooth.comp in three separable passes.
// A share [k0, k1) (SPEC 13) runs the z pass over its own slices; the z pass
// reads the x-y sums of the slices [k0 - r, k1 + r). A share that continues the
// previous call's sweep (same cld and radius, k0 where that share ended) finds
// the sums up to its k0 + r in SmoothSumXY already and runs the x and y passes
// over the rest only; any other share sums its whole halo.
#include <algorithm>

#include "impl_vk/BackendVk.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/SmoothVkState.h"

namespace cb::vk {

Status BackendVk::Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) {
    SmoothVkState& state = mStages.Get<SmoothVkState>();
    if (radius < 0 || radius > 2) return MakeError("vk: smooth radius must be 0, 1 or 2");
    const Extent3 e = cld.Extent();
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    const std::optional<SmoothVkState::Sweep> sweep = std::exchange(state.sweep, std::nullopt);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const uint32_t r = uint32_t(radius);
    // The slices whose x-y sums this call computes: [sum0, sum1).
    const bool continues = k0 > 0 && sweep && sweep->cld == &cld && sweep->radius == radius && sweep->next == k0;
    const uint32_t sum1 = std::min(e.nz, k1 + r);
    const uint32_t sum0 = std::min(sum1, continues ? sweep->summedTo : (k0 > r ? k0 - r : 0));
    auto pipeline =
        mContext->GetPipeline("smooth", 4, slices.IsWhole(e.nz) ? PipelineRange::Whole : PipelineRange::Share);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto sumX = Scratch(state.sumX, e.Count() * 4);
    if (!sumX) return std::unexpected(sumX.error());
    auto sumXY = Scratch(state.sumXY, e.Count() * 4);
    if (!sumXY) return std::unexpected(sumXY.error());
    SmoothPush push{e.nx, e.ny, e.nz, (e.nx + 31) / 32, radius, 1.0f / float(SmoothNormaliser(radius)), 0, 0, 0};
    const DeviceBuffer* buffers[] = {&Dev(cld), *sumX, *sumXY, &Dev(q)};
    CB_TRY(Record("smooth", [&](VulkanContext::Recorder& rec) {
        for (push.pass = 0; push.pass < 3; ++push.pass) {
            push.first = e.nx * e.ny * (push.pass < 2 ? sum0 : k0);
            push.end = e.nx * e.ny * (push.pass < 2 ? sum1 : k1);
            if (push.first == push.end) continue;
            if (push.pass > 0) rec.Barrier();
            rec.DispatchRange(**pipeline, buffers, &push, sizeof push, push.first, push.end);
        }
    }));
    if (k1 < e.nz) state.sweep = SmoothVkState::Sweep{&cld, radius, k1, sum1};
    return {};
}

}  // namespace cb::vk
