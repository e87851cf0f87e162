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

#include "core/pipeline/Backend.h"
#include "core/pipeline/MarchGpu.h"
#include "core/pipeline/StageObjects.h"
#include "impl_vk/CaVkState.h"
#include "impl_vk/DensityVkState.h"
#include "impl_vk/NoiseVkState.h"
#include "impl_vk/RegionVkState.h"
#include "impl_vk/RenderLayersVkState.h"
#include "impl_vk/RenderMarchVkState.h"
#include "impl_vk/RenderSplatVkState.h"
#include "impl_vk/ScratchVk.h"
#include "impl_vk/ShadeVkState.h"
#include "impl_vk/SkyVolumeVk.h"
#include "impl_vk/SmoothVkState.h"
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

// The device limits as Backend::Limits lists them, each with what it bounds in a scene.
std::vector<DeviceLimit> DescribeVkLimits(const VkPhysicalDeviceLimits& limits);
// The first setting of `scene` past `limits` on vk (Backend::ExceededLimit).
std::optional<LimitExceeded> FindExceededVkLimit(const VkPhysicalDeviceLimits& limits, const Scene& scene);

class BackendVk final : public Backend {
  public:
    // device: index, name substring or "" (first device); validation: Khronos layer on.
    static Result<std::unique_ptr<BackendVk>> Create(const std::string& device, bool validation);
    // Buffers made by CreateBuffer must be destroyed before the backend.
    ~BackendVk() override;

    std::string Name() const override { return "vk"; }
    std::string Device() const override { return mContext->DeviceName(); }
    bool Supports(Stage stage) const override { return StagesVk::Implements(stage); }

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    // Bit fields as rows of ceil(nx/32) 32-bit words, bytes as bytes, floats as
    // floats, each buffer padded to a multiple of 4 bytes.
    uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const override;
    // The sum of the stage objects' (each says what it counts in its <Stage>VkState.h).
    // The stage objects' and, with shafts of light, the shafts pass's block.
    uint64_t ScratchBytes(const Scene& scene) const override {
        return mStages.ScratchBytes(scene) + (scene.lighting.shafts.on ? sizeof(ShaftsFrame) : 0);
    }
    // The largest device-local heap.
    std::optional<uint64_t> AvailableBytes() const override { return mContext->LargestDeviceLocalHeap(); }
    // The device's workgroup count and storage buffer range.
    std::vector<DeviceLimit> Limits() const override { return DescribeVkLimits(mContext->DeviceLimits()); }
    std::optional<LimitExceeded> ExceededLimit(const Scene& scene) const override {
        if (auto unbuilt = MarchReprojectionNotBuilt(scene, "vk")) return unbuilt;
        return FindExceededVkLimit(mContext->DeviceLimits(), scene);
    }

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_SKY_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_NOISE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_MARCH_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_LAYERS_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    Status AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) override;

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
    // The stage objects (core/pipeline/StageObjects.h): each stage's device
    // buffers and what it keeps between calls, in its <Stage>VkState.h.
    using StagesVk = StageObjects<RegionVkState, CaVkState, SmoothVkState, DensityVkState, ShadeVkState,
                                  ShadeSkyVkState, NothingKept<Stage::Shadow>, RenderSplatVkState, NoiseVkState,
                                  RenderMarchVkState, RenderLayersVkState>;

    explicit BackendVk(std::unique_ptr<VulkanContext> context) : mContext(std::move(context)) {}
    // Records with `fn`, submits, waits and keeps the device time (defined below the class).
    template <typename Fn>
    Status Record(const char* what, Fn&& fn);
    // The slot's buffer, grown to at least `size` bytes; its contents are undefined.
    Result<DeviceBuffer*> Scratch(BufferSlot& slot, VkDeviceSize size);
    // The slot's buffer (at least `minSize` bytes) holding `bytes` from offset 0,
    // uploaded only when they differ from what this last uploaded there; for
    // slots the host writes and no shader does (the shares of a stage upload
    // the same list once).
    Result<DeviceBuffer*> ScratchHolding(BufferSlot& slot, std::span<const std::byte> bytes, VkDeviceSize minSize);
    // The slot's buffer holding kMieCloudTable's values (uploaded once, by ScratchHolding): the phase_table.glsl
    // table of the renderers with phase Mie.
    Result<DeviceBuffer*> MiePhaseTable(BufferSlot& slot);
    // Shade's sweep (ShadeVk.cpp) from q into T with `state`'s coarse grids: the sun's T (Shade) or the sky
    // light's T_sky (ShadeSky); `stage` names it in errors.
    Status ShadeInto(ShadeVkState& state, const char* stage, const ShadeParams& params, const Buffer& q, Buffer& T);
    // The pass that forms T_sky's padded volume in the slot's buffer (SkyVolumeVk.h), `tiling` wrapping it; with
    // TSky null (no sky light) none, and `standIn` bound in its place.
    Result<SkyVolumePass> PrepareSkyVolume(BufferSlot& slot, const Buffer* TSky, bool tiling,
                                           const DeviceBuffer* standIn);

    std::unique_ptr<VulkanContext> mContext;
    StagesVk mStages;  // after mContext: their buffers are destroyed before it
    BufferSlot mShaftsFrame;  // the shafts pass's block (ShaftsVk.cpp); after mContext likewise
    std::optional<double> mLastDeviceMs;
    ShadeSweep mShadeSweep = ShadeSweep::Auto;
    uint32_t mSplatChunkRanks = 0;
    std::vector<DeferredHostResult> mDeferredResults;  // this batch's, so far (TakeDeferredResults)
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
