// The Vulkan backend's façade: the context, buffers and their transfers, and
// the helpers every stage shares (Record and Dev in BackendVk.h, Scratch). The host side
// of each stage is in its own file: RegionVk.cpp, CaVk.cpp, SmoothVk.cpp,
// DensityVk.cpp, ShadeVk.cpp, ShadowVk.cpp, RenderSplatVk.cpp.
#include "impl_vk/BackendVk.h"

#include <algorithm>
#include <vector>

#include "core/math/NoiseGpu.h"
#include "core/pipeline/MarchGpu.h"
#include "core/scene/Scene.h"

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

Result<std::unique_ptr<BackendVk>> BackendVk::Create(const std::string& device, bool validation) {
    auto context = VulkanContext::Create(device, validation);
    if (!context) return std::unexpected(Error{"vk: " + context.error().message});
    return std::unique_ptr<BackendVk>(new BackendVk(std::move(*context)));
}

BackendVk::~BackendVk() {
    for (DeviceBuffer& b : mScratch) mContext->DestroyBuffer(b);
}

bool BackendVk::Supports(Stage stage) const {
    return IsSplatPipelineStage(stage) || stage == Stage::Noise || stage == Stage::RenderMarch;
}

Result<DeviceBuffer*> BackendVk::Scratch(VkScratch slot, VkDeviceSize size) {
    DeviceBuffer& b = mScratch.at(size_t(slot));
    if (b.size < size) {
        mScratchHeld.at(size_t(slot)).reset();
        mContext->DestroyBuffer(b);
        auto created = mContext->CreateBuffer(size);
        if (!created) return std::unexpected(created.error());
        b = *created;
    }
    return &b;
}

Result<DeviceBuffer*> BackendVk::ScratchHolding(VkScratch slot, std::span<const std::byte> bytes,
                                                VkDeviceSize minSize) {
    auto b = Scratch(slot, std::max<VkDeviceSize>(minSize, bytes.size()));
    if (!b) return b;
    auto& held = mScratchHeld.at(size_t(slot));
    if (held && std::equal(held->begin(), held->end(), bytes.begin(), bytes.end())) return b;
    held.reset();
    if (!bytes.empty()) CB_TRY(mContext->Upload(**b, bytes));
    held.emplace(bytes.begin(), bytes.end());
    return b;
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

uint64_t BackendVk::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    uint64_t bytes = 0;
    // ca with wind: the rules' three outputs before advection (CaVk.cpp).
    if (scene.stages.Has(Stage::Ca) && scene.ca.HasWind()) bytes += 3 * BufferBytes(BufferFormat::Bits, e);
    // smooth: the sums along x and along x and y, a uint per voxel each (SmoothVk.cpp).
    if (scene.stages.Has(Stage::Smooth)) bytes += 2 * e.Count() * 4;
    // shade below full resolution: q and T on the coarse grid, ceil(n / f) cells per axis (ShadeVk.cpp).
    if (const uint32_t f = uint32_t(std::max(scene.shade.resolution, 1)); scene.stages.Has(Stage::Shade) && f > 1)
        bytes += 2 * Extent3{CeilDiv(e.nx, f), CeilDiv(e.ny, f), CeilDiv(e.nz, f)}.Count() * 4;
    // noise: the data block (core/math/NoiseGpu.h): header, two tables, HD per slice, towers, detail volume.
    if (scene.stages.Has(Stage::Noise)) bytes += noise::GpuDataBytes(scene.noise, e);
    // render_march: the constants, the padded volume (T only with light "shade"), a word per brick with
    // skipping, the Mie table with phase Mie, the counters (RenderMarchVk.cpp).
    if (scene.stages.Has(Stage::RenderMarch)) {
        bytes += sizeof(MarchGpu) + MarchVolumeBytes(e, scene.march.light == MarchLightSource::Shade) + 10 * 4;
        if (scene.march.skipping) {
            const auto b = MarchBrickCounts(e, scene.march.brick);
            bytes += uint64_t(b[0]) * b[1] * b[2] * 4;
        }
        if (scene.phase.kind == PhaseKind::Mie) bytes += uint64_t(kMieCloudTable.count) * 4;
    }
    return bytes;
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
