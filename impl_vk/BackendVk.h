// The Vulkan compute backend. Buffers live in device memory in the backend's
// own layouts: bit fields as 32 voxels per uint along x (rows of ceil(nx/32)
// words), byte volumes as bytes (storageBuffer8BitAccess), floats as floats.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Noise.h"
#include "core/pipeline/Backend.h"
#include "impl_vk/VulkanContext.h"

namespace cb::vk {

class BufferVk final : public Buffer {
  public:
    BufferVk(BufferFormat format, Extent3 extent, VulkanContext& context, DeviceBuffer buffer)
        : Buffer(format, extent), mContext(context), mBuffer(buffer) {}
    ~BufferVk() override { mContext.DestroyBuffer(mBuffer); }
    const DeviceBuffer& Device() const { return mBuffer; }
    uint32_t WordsPerRow() const { return (Extent().nx + 31) / 32; }

  private:
    VulkanContext& mContext;
    DeviceBuffer mBuffer;
};

// The backend's reusable device buffers (BackendVk::Scratch). Each slot belongs
// to one stage, keeps its contents only within a call (except ShadeCoarseQ/T
// and SmoothSumXY, which carry a sweep from one share to the next, SPEC 13) and
// grows to the largest size asked of it.
enum class VkScratch {
    EllipsoidList,          // region: the ellipsoids, 32 bytes each
    RegionTileStarts,       // region: first RegionTileEntries index per 16x16 tile of a slice, and one past the end
    RegionTileEntries,      // region: ellipsoid indices, tile by tile
    CaRulesHum,             // ca: the rules' hum before advection (only with wind)
    CaRulesAct,             // ca: the rules' act before advection (only with wind)
    CaRulesCld,             // ca: the rules' cld before advection (only with wind)
    CaWindShifts,           // ca: (shiftX, shiftY) per slice (only with wind)
    SmoothSumX,             // smooth: the bit field summed along x
    SmoothSumXY,            // smooth: those sums summed along y; kept between the shares of a sweep
    CoverCounter,           // density: covered columns, one uint
    ShadeCoarseQ,           // shade: q on the coarse grid (resolution 2 or 4); kept between the shares of a sweep
    ShadeCoarseT,           // shade: T on the coarse grid (resolution 2 or 4); kept between the shares of a sweep
    SplatFrame,             // render_splat: grid, camera and light (the shaders' Frame)
    SplatRankParts,         // render_splat: per position of each axis order, its coordinate and index shares
    SplatBoxes,             // render_splat: visibility of each tile x band box, one byte each
    SplatCandidates,        // render_splat: a bit per rank, 1 where it makes a splat
    SplatChunkSplats,       // render_splat: splats per chunk of ranks
    SplatChunkPairs,        // render_splat: (screen tile, splat) pairs per chunk of ranks
    SplatChunkOffsets,      // render_splat: SplatChunkSplats scanned, and the total
    SplatChunkPairOffsets,  // render_splat: SplatChunkPairs scanned, and the total
    SplatTotals,  // render_splat: the splats, the pairs, and 64 slots of voxels visited and fragments, read by the host
    Splats,       // render_splat: the splats in the shared order, 48 bytes each
    SplatTiles,   // render_splat: screen tiles per splat
    SplatPairOffsets,  // render_splat: SplatTiles scanned, and the total
    SplatKeys,         // render_splat: the pairs' screen tiles (radix sort ping)
    SplatValues,       // render_splat: the pairs' splat indices (radix sort ping)
    SplatKeysSwap,     // render_splat: the pairs' screen tiles (radix sort pong)
    SplatValuesSwap,   // render_splat: the pairs' splat indices (radix sort pong)
    SplatSortCounts,   // render_splat: pairs per radix digit x sort block
    SplatSortOffsets,  // render_splat: SplatSortCounts scanned, and the total
    SplatTileBases,    // render_splat: the first sorted pair of each screen tile, and the pairs
    SplatScanSums,     // render_splat: the block sums of its scans (scan.comp)
    NoiseData,         // noise: the scene's data block (core/math/NoiseGpu.h), kept while mNoiseForm's scene stays
    MarchFrame,        // render_march: the constants (core/pipeline/MarchGpu.h), 256 bytes
    MarchVolume,       // render_march: the padded volume, (q_alpha, T) pairs with light "shade", else q_alpha
    MarchBricks,       // render_march: one word per brick, 1 iff empty (only with skipping)
    MarchMieTable,     // render_march: kMieCloudTable's values, uploaded once (only with phase Mie)
    MarchStats,        // render_march: the MarchStats counters, 64-bit as two words each
    GroundFrame,       // render_splat, render_march with the ground: the GroundGpu block (core/math/Ground.h)
    Count
};

// Bytes of render_march's padded volume on a grid of extent e: (q, T) pairs, or q alone.
uint64_t MarchVolumeBytes(const Extent3& e, bool withT);

class BackendVk final : public Backend {
  public:
    // device: index, name substring or "" (first device); validation: Khronos layer on.
    static Result<std::unique_ptr<BackendVk>> Create(const std::string& device, bool validation);
    // Buffers made by CreateBuffer must be destroyed before the backend.
    ~BackendVk() override;

    std::string Name() const override { return "vk"; }
    std::string Device() const override { return mContext->DeviceName(); }
    bool Supports(Stage stage) const override;

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    // Bit fields as rows of ceil(nx/32) 32-bit words, bytes as bytes, floats as
    // floats, each buffer padded to a multiple of 4 bytes.
    uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const override;
    // The automaton's rule outputs with wind, smooth's two sum volumes, shade's
    // coarse q and T below full resolution, noise's data block; the region's and the renderer's
    // lists (which depend on the ellipsoids and the clouds) are not counted.
    uint64_t ScratchBytes(const Scene& scene) const override;
    // The largest device-local heap.
    std::optional<uint64_t> AvailableBytes() const override { return mContext->LargestDeviceLocalHeap(); }

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_NOISE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_MARCH_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)

    // Pipelined timing (core/pipeline/Backend.h): the context records the batch into one
    // command buffer (VulkanContext::BeginBatch); a Download inside it, and
    // render_splat's counts (which size its next passes), submit and wait once
    // each. Density's cover is deferred: read after the batch's wait.
    Status BeginBatch() override {
        mDeferredResults.clear();
        return mContext->BeginBatch();
    }
    void MarkBatch() override { mContext->MarkBatch(); }
    Result<std::vector<double>> EndBatch() override { return mContext->EndBatch(); }
    std::vector<DeferredHostResult> TakeDeferredResults() override { return std::exchange(mDeferredResults, {}); }
    SubmissionCounts Submissions() const override { return {mContext->Submissions(), mContext->HostWaits()}; }

    // How shade sweeps its slices (ShadeVk.cpp): one dispatch per slice (the
    // reference), or blocks of slices per dispatch. Auto: per slice on a CPU
    // device (lavapipe, where the blocks' extra cells cost more than the
    // dispatches they save; docs/performance.md), blocks on a GPU. Both give the
    // same T, bit for bit.
    enum class ShadeSweep : uint8_t { Auto, PerSlice, Blocks };
    void SetShadeSweep(ShadeSweep sweep) { mShadeSweep = sweep; }
    // Ranks per invocation of render_splat's count and write passes (RenderSplatVk.cpp),
    // a multiple of 32; 0 (the default): 1024 on a CPU device, where an invocation's
    // loop is cheap and dispatch slots dear, 32 on a GPU, for 32 x more invocations.
    // The image is the same, bit for bit.
    void SetSplatChunkRanks(uint32_t ranks) { mSplatChunkRanks = ranks; }
    // Dispatches recorded since the backend was made.
    uint64_t Dispatches() const { return mContext->Dispatches(); }

    // Device time of the last stage call (timestamp queries), in ms.
    std::optional<double> LastDeviceMs() const override { return mLastDeviceMs; }
    uint32_t ValidationMessages() const { return mContext->ValidationMessages(); }

  private:
    explicit BackendVk(std::unique_ptr<VulkanContext> context) : mContext(std::move(context)) {}
    // Records with `fn`, submits, waits and keeps the device time (defined below the class).
    template <typename Fn>
    Status Record(const char* what, Fn&& fn);
    // The slot's buffer, grown to at least `size` bytes; its contents are undefined.
    Result<DeviceBuffer*> Scratch(VkScratch slot, VkDeviceSize size);
    // The slot's buffer (at least `minSize` bytes) holding `bytes` from offset 0,
    // uploaded only when they differ from what this last uploaded there; for
    // slots the host writes and no shader does (the shares of a stage upload
    // the same list once).
    Result<DeviceBuffer*> ScratchHolding(VkScratch slot, std::span<const std::byte> bytes, VkDeviceSize minSize);

    std::unique_ptr<VulkanContext> mContext;
    std::optional<double> mLastDeviceMs;
    ShadeSweep mShadeSweep = ShadeSweep::Auto;
    uint32_t mSplatChunkRanks = 0;
    std::vector<DeferredHostResult> mDeferredResults;  // this batch's, so far (TakeDeferredResults)
    // Indexed by VkScratch. A fixed array, so pointers to one slot stay valid
    // while others grow.
    std::array<DeviceBuffer, size_t(VkScratch::Count)> mScratch{};
    // What ScratchHolding last uploaded into each slot; reset when the slot grows.
    std::array<std::optional<std::vector<std::byte>>, size_t(VkScratch::Count)> mScratchHeld{};
    // noise: the scene whose data block is in the NoiseData slot (NoiseVk.cpp).
    std::unique_ptr<noise::NoiseForm> mNoiseForm;
    // render_march: kMieCloudTable is in the MarchMieTable slot (RenderMarchVk.cpp).
    bool mMieUploaded = false;
    // smooth: the share sequence whose x-y sums are in the SmoothSumXY slot: the
    // slices [0, summedTo) of `cld` at `radius`, its next share starting at `next`
    // (SmoothVk.cpp). Reset by every smooth call that does not continue it.
    struct SmoothSweep {
        const Buffer* cld = nullptr;
        int radius = 0;
        uint32_t next = 0, summedTo = 0;
    };
    std::optional<SmoothSweep> mSmoothSweep;
};

// For the stages' host files (<Stage>Vk.cpp) and the façade.

// The device buffer behind a Buffer; only buffers made by BackendVk::CreateBuffer.
inline const DeviceBuffer& Dev(const Buffer& b) { return static_cast<const BufferVk&>(b).Device(); }

// Records with `fn`, submits, waits; the submit's device time becomes LastDeviceMs().
template <typename Fn>
Status BackendVk::Record(const char* what, Fn&& fn) {
    auto ms = mContext->Run(what, std::forward<Fn>(fn));
    if (!ms) return std::unexpected(ms.error());
    mLastDeviceMs = *ms;
    return {};
}

}  // namespace cb::vk
