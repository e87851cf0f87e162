// Stage `density` (SPEC 5) on Vulkan: column sums and the cover count
// (density.comp), then tile/band occupancy (occupancy.comp). A share (SPEC 13)
// is a range of rows of tiles: both dispatches cover those rows only, and the
// cover counts those rows' columns.
#include <algorithm>

#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::Density(const DensityParams& params, const Buffer& q, const Buffer* cld, DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("vk: density tile and band must be positive");
    const Extent3 e = q.Extent();
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t row0 = params.slices.Begin(tilesY), row1 = params.slices.End(tilesY);
    if (row0 >= row1) {
        out.coveredColumns = 0;
        mLastDeviceMs = 0.0;
        return {};
    }
    const uint32_t j0 = row0 * params.tile, j1 = std::min(e.ny, row1 * params.tile);  // the rows' columns
    auto columns = mContext->GetPipeline("density", 4,
                                         params.slices.IsWhole(tilesY) ? PipelineRange::Whole : PipelineRange::Share);
    if (!columns) return std::unexpected(columns.error());
    auto occupancy = mContext->GetPipeline("occupancy", 4,
                                           params.slices.IsWhole(tilesY) ? PipelineRange::Whole : PipelineRange::Share);
    if (!occupancy) return std::unexpected(occupancy.error());
    auto counter = Scratch(VkScratch::CoverCounter, 4);
    if (!counter) return std::unexpected(counter.error());
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    struct {
        uint32_t nx, ny, nz, words, fromCld, first, end;
    } columnPush{e.nx, e.ny, e.nz, (e.nx + 31) / 32, cld ? 1u : 0u, e.nx * j0, e.nx * j1};
    struct {
        uint32_t nx, ny, nz, tile, band, tilesX, tilesY, bandCount, ty0, tileRows;
    } occupancyPush{e.nx, e.ny, e.nz, params.tile, params.band, tilesX, tilesY, bandCount, row0, row1 - row0};
    // Without cld the cover counts columns with D > 0; q stands in at the unused binding.
    const DeviceBuffer* columnBuffers[] = {&Dev(q), &Dev(cld ? *cld : q), &Dev(*out.columnSum), *counter};
    const DeviceBuffer* occupancyBuffers[] = {&Dev(q), &Dev(*out.columnSum), &Dev(*out.tiles), &Dev(*out.bands)};
    CB_TRY(Record("density", [&](VulkanContext::Recorder& r) {
        r.Fill(**counter, 0);
        r.Barrier();
        r.DispatchRange(**columns, columnBuffers, &columnPush, sizeof columnPush, columnPush.first, columnPush.end);
        r.Barrier();
        r.Dispatch(**occupancy, occupancyBuffers, &occupancyPush, sizeof occupancyPush,
                   tilesX * (row1 - row0) * (bandCount + 1));
    }));
    const double deviceMs = mLastDeviceMs.value_or(0);
    uint32_t covered = 0;
    CB_TRY(mContext->Download(**counter, std::as_writable_bytes(std::span(&covered, 1))));
    mLastDeviceMs = deviceMs;
    out.coveredColumns = covered;
    return {};
}

}  // namespace cb::vk
