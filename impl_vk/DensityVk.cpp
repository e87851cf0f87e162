// Stage `density` (SPEC 5) on Vulkan in one pass (density.comp): one workgroup
// per tile sums its columns (D, bit-exact: each column serially in k order)
// and, from the same read of q, writes the tile's band flags, its tile flag and
// its part of the cover count. A share (SPEC 13) is a range of rows of tiles:
// the dispatch covers those rows' tiles only, and the cover counts their columns.
#include <algorithm>
#include <cstring>
#include <string>

#include "impl_vk/BackendVk.h"
#include "impl_vk/DensityVkState.h"
#include "impl_vk/PushBlocks.h"

namespace cb::vk {

namespace {
constexpr uint32_t kDensityMaxBands = 64 * 32;  // density.comp's kBandWords * 32
}  // namespace

Status BackendVk::Density(const DensityParams& params, const Buffer& q, const Buffer* cld, DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("vk: density tile and band must be positive");
    const Extent3 e = q.Extent();
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    if (bandCount > kDensityMaxBands)
        return MakeError("vk: density supports at most " + std::to_string(kDensityMaxBands) + " bands, not " +
                         std::to_string(bandCount));
    const uint32_t row0 = params.slices.Begin(tilesY), row1 = params.slices.End(tilesY);
    if (row0 >= row1 || tilesX == 0) {
        out.coveredColumns = 0;
        mLastDeviceMs = 0.0;
        return {};
    }
    // The share's rows come from the push constant ty0, so the plain pipeline serves shares too.
    auto pass = mContext->GetPipeline("density", 6);
    if (!pass) return std::unexpected(pass.error());
    auto counter = Scratch(mStages.Get<DensityVkState>().coverCounter, 4);
    if (!counter) return std::unexpected(counter.error());
    DensityPush push{e.nx,        e.ny,   e.nz,   (e.nx + 31) / 32, cld ? 1u : 0u, params.tile,
                     params.band, tilesX, tilesY, bandCount,        row0};
    // Without cld the cover counts columns with D > 0; q stands in at the unused binding.
    const DeviceBuffer* buffers[] = {&Dev(q),  &Dev(cld ? *cld : q), &Dev(*out.columnSum),
                                     *counter, &Dev(*out.tiles),     &Dev(*out.bands)};
    CB_TRY(Record("density", [&](VulkanContext::Recorder& r) {
        r.Fill(**counter, 0);
        r.Barrier();
        r.DispatchGroups(**pass, buffers, &push, sizeof push, tilesX, row1 - row0, 1);
    }));
    if (mContext->InBatch()) {  // the cover after the batch's wait (core/pipeline/Backend.h, deferred host results)
        const uint32_t mark = mContext->Interval();
        return mContext->DownloadLater(**counter, 4, [this, mark](std::span<const std::byte> bytes) {
            uint32_t covered = 0;
            std::memcpy(&covered, bytes.data(), sizeof covered);
            mDeferredResults.push_back({mark, covered, std::nullopt});
        });
    }
    const double deviceMs = mLastDeviceMs.value_or(0);
    uint32_t covered = 0;
    CB_TRY(mContext->Download(**counter, std::as_writable_bytes(std::span(&covered, 1))));
    mLastDeviceMs = deviceMs;
    out.coveredColumns = covered;
    return {};
}

}  // namespace cb::vk
