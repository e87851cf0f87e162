// The Vulkan backend's façade: the context, buffers and their transfers, and
// the helpers every stage shares (Record and Dev in BackendVk.h, Scratch, PrepareSkyVolume). Each
// stage has its object in <Stage>VkState.h (what it keeps between calls and its
// scratch bytes) and its entry in <Stage>Vk.cpp: RegionVk.cpp, CaVk.cpp, ...
#include "impl_vk/BackendVk.h"

#include <algorithm>
#include <vector>

namespace cb::vk {
namespace {

// Bytes of a buffer's contents on the device.
VkDeviceSize DeviceBytes(BufferFormat format, const Extent3& e) {
    switch (format) {
        case BufferFormat::Bits:
            return VkDeviceSize(CeilDiv(e.nx, 32)) * e.ny * e.nz * 4;
        case BufferFormat::U8:
            return VkDeviceSize(e.Count());
        case BufferFormat::F32:
            return VkDeviceSize(e.Count()) * 4;
    }
    return 0;
}

}  // namespace

// Invocations a workgroup of the passes' one-dimensional dispatches runs (VulkanContext::Recorder::Dispatch).
constexpr uint64_t kGroupInvocations = 64;

std::vector<DeviceLimit> DescribeVkLimits(const VkPhysicalDeviceLimits& limits) {
    return {
        {"maxComputeWorkGroupCount[0]", limits.maxComputeWorkGroupCount[0],
         "grid nx * ny * nz, at most " + std::to_string(kGroupInvocations) +
             " times this (a pass dispatches one invocation per voxel, in workgroups of " +
             std::to_string(kGroupInvocations) + " along x)"},
        {"maxStorageBufferRange", limits.maxStorageBufferRange,
         "the bytes of each buffer (a grid of floats: 4 * nx * ny * nz; an image: 12 * render.width * "
         "render.height), each bound whole as a storage buffer"},
    };
}

std::optional<LimitExceeded> FindExceededVkLimit(const VkPhysicalDeviceLimits& limits, const Scene& scene) {
    const Extent3 e = scene.grid.size;
    const uint64_t voxels = e.Count(), groups = (voxels + kGroupInvocations - 1) / kGroupInvocations;
    if (groups > limits.maxComputeWorkGroupCount[0])
        return LimitExceeded{"grid.size", "vk: nx * ny * nz " + std::to_string(voxels) + " needs " +
                                              std::to_string(groups) + " workgroups, more than this device's " +
                                              "maxComputeWorkGroupCount[0] " +
                                              std::to_string(limits.maxComputeWorkGroupCount[0]) +
                                              " (a pass dispatches one invocation per voxel, in workgroups of " +
                                              std::to_string(kGroupInvocations) + " along x)"};
    const uint64_t range = limits.maxStorageBufferRange;
    // `what` of `bytes` bytes past maxStorageBufferRange.
    auto past = [&](const char* field, const std::string& what, uint64_t bytes) -> std::optional<LimitExceeded> {
        if (bytes <= range) return std::nullopt;
        return LimitExceeded{field, "vk: " + what + " takes " + std::to_string(bytes) +
                                        " bytes, more than this device's maxStorageBufferRange " +
                                        std::to_string(range) + " (every buffer is bound whole as a storage buffer)"};
    };
    if (auto found = past("grid.size", "a grid buffer of floats", DeviceBytes(BufferFormat::F32, e))) return found;
    if (scene.stages.Has(Stage::RenderMarch) || scene.stages.Has(Stage::RenderLayers))
        if (auto found = past("grid.size", "the renderer's volume padded by one voxel each side",
                              MarchVolumeBytes(e, scene.stages.Has(Stage::RenderLayers) ||
                                                      scene.march.light == MarchLightSource::Shade)))
            return found;
    if (scene.stages.Has(Stage::RenderSplat) || scene.stages.Has(Stage::RenderMarch) ||
        scene.stages.Has(Stage::RenderLayers)) {
        const Extent3 image{3, scene.render.width, scene.render.height};
        if (auto found = past("render.width",
                              "an image of " + std::to_string(image.ny) + " x " + std::to_string(image.nz) + " pixels",
                              DeviceBytes(BufferFormat::F32, image)))
            return found;
    }
    return std::nullopt;
}

Result<std::unique_ptr<BackendVk>> BackendVk::Create(const std::string& device, bool validation) {
    auto context = VulkanContext::Create(device, validation);
    if (!context) return std::unexpected(Error{"vk: " + context.error().message});
    return std::unique_ptr<BackendVk>(new BackendVk(std::move(*context)));
}

// The stage objects destroy their buffers after this, before the context.
BackendVk::~BackendVk() = default;

Result<DeviceBuffer*> BackendVk::Scratch(BufferSlot& slot, VkDeviceSize size) {
    DeviceBuffer& b = slot.buffer;
    if (b.size < size) {
        slot.held.reset();
        mContext->DestroyBuffer(b);
        auto created = mContext->CreateBuffer(size);
        if (!created) return std::unexpected(created.error());
        b = *created;
        slot.context = mContext.get();
    }
    return &b;
}

Result<DeviceBuffer*> BackendVk::ScratchHolding(BufferSlot& slot, std::span<const std::byte> bytes,
                                                VkDeviceSize minSize) {
    auto b = Scratch(slot, std::max<VkDeviceSize>(minSize, bytes.size()));
    if (!b) return b;
    auto& held = slot.held;
    if (held && std::equal(held->begin(), held->end(), bytes.begin(), bytes.end())) return b;
    held.reset();
    if (!bytes.empty()) CB_TRY(mContext->Upload(**b, bytes));
    held.emplace(bytes.begin(), bytes.end());
    return b;
}

Result<DeviceBuffer*> BackendVk::MiePhaseTable(BufferSlot& slot) {
    return ScratchHolding(slot, std::as_bytes(std::span(kMieCloudTable.values, kMieCloudTable.count)), 0);
}

Result<SkyVolumePass> BackendVk::PrepareSkyVolume(BufferSlot& slot, const Buffer* TSky, bool tiling,
                                                  const DeviceBuffer* standIn) {
    SkyVolumePass pass;
    if (!TSky) {
        pass.buffers = {standIn, standIn};
        return pass;
    }
    const Extent3 e = TSky->Extent();
    auto pipeline = mContext->GetPipeline("sky_volume", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto volume = Scratch(slot, SkyVolumeBytes(e));
    if (!volume) return std::unexpected(volume.error());
    pass.pipeline = *pipeline;
    pass.buffers = {&Dev(*TSky), *volume};
    pass.push = {e.nx, e.ny, e.nz, tiling ? 1u : 0u};
    return pass;
}

Result<std::unique_ptr<Buffer>> BackendVk::CreateBuffer(BufferFormat format, Extent3 extent) {
    if (extent.Count() == 0) return MakeError("vk: cannot create an empty buffer");
    auto device = mContext->CreateBuffer(DeviceBytes(format, extent));
    if (!device) return std::unexpected(Error{"vk: " + device.error().message});
    return std::make_unique<BufferVk>(format, extent, *mContext, *device);
}

uint64_t BackendVk::BufferBytes(BufferFormat format, const Extent3& extent) const {
    return VulkanContext::StorageBufferBytes(DeviceBytes(format, extent));
}

Status BackendVk::Upload(Buffer& buffer, std::span<const std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("vk: upload size does not match the buffer");
    if (buffer.Format() != BufferFormat::Bits) return mContext->Upload(Dev(buffer), canonical);
    const std::vector<uint32_t> packed = PackBits32(canonical, buffer.Extent());
    return mContext->Upload(Dev(buffer), std::as_bytes(std::span(packed)));
}

Status BackendVk::Download(const Buffer& buffer, std::span<std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("vk: download size does not match the buffer");
    if (buffer.Format() != BufferFormat::Bits) return mContext->Download(Dev(buffer), canonical);
    const Extent3 e = buffer.Extent();
    std::vector<uint32_t> packed(size_t(CeilDiv(e.nx, 32)) * e.ny * e.nz);
    CB_TRY(mContext->Download(Dev(buffer), std::as_writable_bytes(std::span(packed))));
    UnpackBits32(packed, e, canonical);
    return {};
}

}  // namespace cb::vk
