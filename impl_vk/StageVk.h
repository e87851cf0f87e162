// What the host side of every Vulkan stage shares (RegionVk.cpp ... RenderSplatVk.cpp
// and the façade BackendVk.cpp); private to impl_vk.
#pragma once

#include <utility>

#include "impl_vk/BackendVk.h"

namespace cb::vk {

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
