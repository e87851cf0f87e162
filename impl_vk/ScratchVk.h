// The scratch a vk stage object owns (core/pipeline/StageObjects.h): device
// buffers kept between calls, grown by the façade (BackendVk::Scratch,
// ScratchHolding) to the largest size asked of each, and destroyed with the
// object that holds them, before the façade's context.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "impl_vk/VulkanContext.h"

namespace cb::vk {

class BufferSlot {
  public:
    BufferSlot() = default;
    BufferSlot(const BufferSlot&) = delete;
    BufferSlot& operator=(const BufferSlot&) = delete;
    ~BufferSlot() {
        if (context) context->DestroyBuffer(buffer);
    }

    VulkanContext* context = nullptr;  // the one that made `buffer`
    DeviceBuffer buffer;
    // What ScratchHolding last uploaded into it; reset when it grows.
    std::optional<std::vector<std::byte>> held;
};

}  // namespace cb::vk
