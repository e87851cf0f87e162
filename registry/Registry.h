// The backend registry: which backends this build has, how to make one by
// name, and the devices and contexts they can run on. The one library that
// knows the concrete backends; the harness and the tests go through it and
// include no backend's own header for it.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "core/pipeline/Backend.h"
#include "impl_cpu/CpuIsa.h"
#include "impl_gl/GLOptions.h"

namespace cb {

// How a backend is made; each backend reads its own fields.
struct BackendOptions {
    int cpuThreads = 0;         // 0: every hardware thread
    std::string vkDevice;       // Vulkan device index or name substring; "" = the first
    bool vkValidation = false;  // Khronos validation layer (also CLOUDBENCH_VK_VALIDATION=1)
    gl::ContextKind glContext = gl::ContextKind::OSMesa;
    gl::CaLayout glCaLayout = gl::CaLayout::Packed;
};

// The backends compiled into this build, in preference order.
std::vector<std::string> BuiltBackends();

// Creates a backend by name. An unknown name, or one whose device is missing,
// comes back as an Error that says why (the harness reports it and goes on).
Result<std::unique_ptr<Backend>> CreateBackend(const std::string& name, const BackendOptions& options = {});

// One Vulkan physical device, as --vk-device selects it.
struct VulkanDeviceInfo {
    uint32_t index = 0;
    std::string name;
    std::string type;    // "cpu", "integrated GPU", "discrete GPU", ...
    std::string api;     // the device's Vulkan version, "1.3"
    std::string driver;  // driver name and version info; "?" before Vulkan 1.2
    std::vector<DeviceLimit> limits;  // the limits the vk backend checks a scene against (Backend::Limits)
};

// The Vulkan devices here, in --vk-device index order. An Error says why there
// are none, or that this build has no Vulkan backend.
Result<std::vector<VulkanDeviceInfo>> ListVulkanDevices();

// One OpenGL context kind, as --gl-context selects it, tried here.
struct GLContextInfo {
    gl::ContextKind kind = gl::ContextKind::OSMesa;
    bool available = false;
    std::string renderer;  // GL_RENDERER, when available
    std::string version;   // GL_VERSION, when available
    // The texture limits every buffer meets (a 2-D texture array: nx or its 32-bit words by ny, nz layers; an image
    // of W x H pixels has H layers), when available.
    int32_t maxTextureSize = 0;  // GL_MAX_TEXTURE_SIZE
    int32_t maxArrayLayers = 0;  // GL_MAX_ARRAY_TEXTURE_LAYERS
    std::vector<DeviceLimit> limits;  // the limits the gl backend checks a scene against (Backend::Limits)
    std::string reason;    // why it cannot be created, when not
};

// Every context kind in kContextKindNames order, each created and dropped
// again. An Error when this build has no OpenGL backend.
Result<std::vector<GLContextInfo>> ListGLContexts();

}  // namespace cb
