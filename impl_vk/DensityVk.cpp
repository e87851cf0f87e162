// Stage `density` (SPEC 5) on Vulkan: column sums and the cover count
// (density.comp), then tile/band occupancy (occupancy.comp).
#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::Density(const DensityParams& params, const Buffer& q, const Buffer* cld, DensityOutputs& out) {
    if (params.slices != SliceRange{}) return MakeError("vk: density in shares (time-slicing) is not implemented yet");
    if (params.tile == 0 || params.band == 0) return MakeError("vk: density tile and band must be positive");
    const Extent3 e = q.Extent();
    auto columns = mContext->GetPipeline("density", 4);
    if (!columns) return std::unexpected(columns.error());
    auto occupancy = mContext->GetPipeline("occupancy", 4);
    if (!occupancy) return std::unexpected(occupancy.error());
    auto counter = Scratch(VkScratch::CoverCounter, 4);
    if (!counter) return std::unexpected(counter.error());
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    struct {
        uint32_t nx, ny, nz, words, fromCld;
    } columnPush{e.nx, e.ny, e.nz, (e.nx + 31) / 32, cld ? 1u : 0u};
    struct {
        uint32_t nx, ny, nz, tile, band, tilesX, tilesY, bandCount;
    } occupancyPush{e.nx, e.ny, e.nz, params.tile, params.band, tilesX, tilesY, bandCount};
    // Without cld the cover counts columns with D > 0; q stands in at the unused binding.
    const DeviceBuffer* columnBuffers[] = {&Dev(q), &Dev(cld ? *cld : q), &Dev(*out.columnSum), *counter};
    const DeviceBuffer* occupancyBuffers[] = {&Dev(q), &Dev(*out.columnSum), &Dev(*out.tiles), &Dev(*out.bands)};
    CB_TRY(Record("density", [&](VulkanContext::Recorder& r) {
        r.Fill(**counter, 0);
        r.Barrier();
        r.Dispatch(**columns, columnBuffers, &columnPush, sizeof columnPush, e.nx * e.ny);
        r.Barrier();
        r.Dispatch(**occupancy, occupancyBuffers, &occupancyPush, sizeof occupancyPush,
                   tilesX * tilesY * (bandCount + 1));
    }));
    const double deviceMs = mLastDeviceMs.value_or(0);
    uint32_t covered = 0;
    CB_TRY(mContext->Download(**counter, std::as_writable_bytes(std::span(&covered, 1))));
    mLastDeviceMs = deviceMs;
    out.coveredColumns = covered;
    return {};
}

}  // namespace cb::vk
