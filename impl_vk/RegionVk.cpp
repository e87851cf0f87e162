// Stage `region` (SPEC 2) on Vulkan: the host bins the ellipsoids by 16x16 tile of
// each slice (RegionTileLists.h); region.comp takes the max over a voxel's tile list.
#include <algorithm>
#include <vector>

#include "impl_vk/BackendVk.h"
#include "impl_vk/PushBlocks.h"
#include "impl_vk/RegionTileLists.h"
#include "impl_vk/RegionVkState.h"

namespace cb::vk {

Status BackendVk::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region, SliceRange slices) {
    RegionVkState& state = mStages.Get<RegionVkState>();
    const Extent3 e = region.Extent();
    // The share's slices [k0, k1): lists for those slices only, one dispatch over them.
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    static_assert(sizeof(RasterEllipsoid) == 8 * sizeof(float));
    auto list = ScratchHolding(state.ellipsoids, std::as_bytes(ellipsoids), 32);
    if (!list) return std::unexpected(list.error());
    // Per 16x16 tile of each slice of the share, the ellipsoids that can reach it (RegionTileLists.h).
    const RegionTileLists lists = BuildRegionTileLists(ellipsoids, e, k0, k1);
    auto starts = Scratch(state.tileStarts, lists.starts.size() * 4);
    if (!starts) return std::unexpected(starts.error());
    CB_TRY(mContext->Upload(**starts, std::as_bytes(std::span(lists.starts))));
    auto entries = Scratch(state.tileEntries, std::max<size_t>(16, lists.entries.size() * 4));
    if (!entries) return std::unexpected(entries.error());
    if (!lists.entries.empty()) CB_TRY(mContext->Upload(**entries, std::as_bytes(std::span(lists.entries))));
    auto pipeline =
        mContext->GetPipeline("region", 4, slices.IsWhole(e.nz) ? PipelineRange::Whole : PipelineRange::Share);
    if (!pipeline) return std::unexpected(pipeline.error());
    RegionPush push{e.nx, e.ny, k0, e.nx * e.ny * k0, e.nx * e.ny * k1, lists.tilesX, lists.tilesY};
    const DeviceBuffer* buffers[] = {*list, &Dev(region), *starts, *entries};
    return Record("region", [&](VulkanContext::Recorder& r) {
        r.DispatchRange(**pipeline, buffers, &push, sizeof push, push.first, push.end);
    });
}

}  // namespace cb::vk
