// The Vulkan compute backend. Buffers live in device memory in the backend's
// own layouts: bit fields as 32 voxels per uint along x (rows of ceil(nx/32)
// words), byte volumes as bytes (storageBuffer8BitAccess), floats as floats.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>

#include "core/Backend.h"
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

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)

    // Device time of the last stage call (timestamp queries), in ms.
    std::optional<double> LastDeviceMs() const override { return mLastDeviceMs; }
    uint32_t ValidationMessages() const { return mContext->ValidationMessages(); }

  private:
    explicit BackendVk(std::unique_ptr<VulkanContext> context) : mContext(std::move(context)) {}
    template <typename Fn>
    Status Record(const char* what, Fn&& fn);
    Result<DeviceBuffer*> Scratch(size_t slot, VkDeviceSize size);

    std::unique_ptr<VulkanContext> mContext;
    std::optional<double> mLastDeviceMs;
    // Reused between calls: 0 ellipsoids, 1-3 advection, 4 shifts, 5 cover
    // counter, 6-7 coarse shading grids, 8-18 the splat renderer's buffers.
    // A fixed array, so pointers to one slot stay valid while others grow.
    std::array<DeviceBuffer, 23> mScratch{};
};

}  // namespace cb::vk
