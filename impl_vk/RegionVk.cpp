// Stage `region` (SPEC 2) on Vulkan: the host bins the ellipsoids by 16x16 tile of
// each slice; region.comp takes the max over a voxel's tile list.
#include <algorithm>
#include <cmath>
#include <vector>

#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region, SliceRange slices) {
    const Extent3 e = region.Extent();
    // The share's slices [k0, k1): lists for those slices only, one dispatch over them.
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    static_assert(sizeof(RasterEllipsoid) == 8 * sizeof(float));
    auto list = ScratchHolding(VkScratch::EllipsoidList, std::as_bytes(ellipsoids), 32);
    if (!list) return std::unexpected(list.error());
    // Per 16x16 tile of each slice of the share, the ellipsoids whose bounding box (the
    // shader's rejection test, widened by a voxel) reaches a voxel centre of it.
    constexpr uint32_t kTile = 16;
    const uint32_t tilesX = CeilDiv(e.nx, kTile), tilesY = CeilDiv(e.ny, kTile);
    std::vector<uint32_t> tileStart(size_t(tilesX) * tilesY * (k1 - k0) + 1, 0), tileList;
    for (uint32_t k = k0, tile = 0; k < k1; ++k)
        for (uint32_t ty = 0; ty < tilesY; ++ty)
            for (uint32_t tx = 0; tx < tilesX; ++tx, ++tile) {
                const float x0 = float(tx * kTile) + 0.5f, x1 = float(std::min(e.nx, (tx + 1) * kTile) - 1) + 0.5f;
                const float y0 = float(ty * kTile) + 0.5f, y1 = float(std::min(e.ny, (ty + 1) * kTile) - 1) + 0.5f;
                const float z = float(k) + 0.5f;
                for (uint32_t n = 0; n < ellipsoids.size(); ++n) {
                    const RasterEllipsoid& el = ellipsoids[n];
                    const float reach = std::max(el.semiAxes[0], el.semiAxes[1]) + 2.0f;
                    if (std::fabs(z - el.center[2]) > el.semiAxes[2] + 2.0f || el.center[0] + reach < x0 ||
                        el.center[0] - reach > x1 || el.center[1] + reach < y0 || el.center[1] - reach > y1)
                        continue;
                    tileList.push_back(n);
                }
                tileStart[tile + 1] = uint32_t(tileList.size());
            }
    auto starts = Scratch(VkScratch::RegionTileStarts, tileStart.size() * 4);
    if (!starts) return std::unexpected(starts.error());
    CB_TRY(mContext->Upload(**starts, std::as_bytes(std::span(tileStart))));
    auto entries = Scratch(VkScratch::RegionTileEntries, std::max<size_t>(16, tileList.size() * 4));
    if (!entries) return std::unexpected(entries.error());
    if (!tileList.empty()) CB_TRY(mContext->Upload(**entries, std::as_bytes(std::span(tileList))));
    auto pipeline =
        mContext->GetPipeline("region", 4, slices.IsWhole(e.nz) ? PipelineRange::Whole : PipelineRange::Share);
    if (!pipeline) return std::unexpected(pipeline.error());
    struct {
        uint32_t nx, ny, k0, first, end, tilesX, tilesY;
    } push{e.nx, e.ny, k0, e.nx * e.ny * k0, e.nx * e.ny * k1, tilesX, tilesY};
    const DeviceBuffer* buffers[] = {*list, &Dev(region), *starts, *entries};
    return Record("region", [&](VulkanContext::Recorder& r) {
        r.DispatchRange(**pipeline, buffers, &push, sizeof push, push.first, push.end);
    });
}

}  // namespace cb::vk
