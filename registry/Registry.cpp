#include "registry/Registry.h"

#include <cstdlib>
#include <cstring>

#include "impl_cpu/BackendCpu.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#include "impl_vk/VulkanContext.h"
#endif
#if CLOUDBENCH_HAVE_GL
#include "impl_gl/BackendGL.h"
#include "impl_gl/GLContext.h"
#endif

namespace cb {

std::vector<std::string> BuiltBackends() {
    std::vector<std::string> names = {"cpu"};
#if CLOUDBENCH_HAVE_VK
    names.push_back("vk");
#endif
#if CLOUDBENCH_HAVE_GL
    names.push_back("gl");
#endif
    return names;
}

Result<std::unique_ptr<Backend>> CreateBackend(const std::string& name, const BackendOptions& options) {
    if (name == "cpu") return std::make_unique<cpu::BackendCpu>(options.cpuThreads);
    if (name == "gl") {
#if CLOUDBENCH_HAVE_GL
        auto backend = gl::BackendGL::Create(options.glContext, options.glCaLayout);
        if (!backend) return std::unexpected(backend.error());
        return std::unique_ptr<Backend>(std::move(*backend));
#else
        return MakeError("gl: the OpenGL backend is not built in this build (configure with CLOUDBENCH_WITH_GL=ON)");
#endif
    }
    if (name == "vk") {
#if CLOUDBENCH_HAVE_VK
        const char* env = std::getenv("CLOUDBENCH_VK_VALIDATION");
        const bool validation = options.vkValidation || (env && std::strcmp(env, "1") == 0);
        auto backend = vk::BackendVk::Create(options.vkDevice, validation);
        if (!backend) return std::unexpected(backend.error());
        return std::unique_ptr<Backend>(std::move(*backend));
#else
        return MakeError("vk: the Vulkan backend is not built in this build (configure with CLOUDBENCH_WITH_VK=ON)");
#endif
    }
    return MakeError(name + ": unknown backend (known: cpu, gl, vk)");
}

Result<std::vector<VulkanDeviceInfo>> ListVulkanDevices() {
#if CLOUDBENCH_HAVE_VK
    auto devices = vk::ListDevices();
    if (!devices) return std::unexpected(devices.error());
    std::vector<VulkanDeviceInfo> out;
    for (const vk::DeviceInfo& d : *devices)
        out.push_back({d.index, d.name, d.type,
                       std::to_string(VK_API_VERSION_MAJOR(d.apiVersion)) + "." +
                           std::to_string(VK_API_VERSION_MINOR(d.apiVersion)),
                       d.driver, vk::DescribeVkLimits(d.limits)});
    return out;
#else
    return MakeError("not built in this build (configure with CLOUDBENCH_WITH_VK=ON)");
#endif
}

Result<std::vector<GLContextInfo>> ListGLContexts() {
#if CLOUDBENCH_HAVE_GL
    std::vector<GLContextInfo> out;
    for (const NamedValue<gl::ContextKind>& entry : gl::kContextKindNames) {
        GLContextInfo info;
        info.kind = entry.value;
        if (auto context = gl::GLContext::Create(entry.value)) {
            info.available = true;
            info.renderer = (*context)->String(GL_RENDERER);
            info.version = (*context)->String(GL_VERSION);
            info.maxTextureSize = (*context)->Integer(GL_MAX_TEXTURE_SIZE);
            info.maxArrayLayers = (*context)->Integer(GL_MAX_ARRAY_TEXTURE_LAYERS);
            info.limits = gl::DescribeGLLimits(gl::ReadGLLimits(**context));
        } else {
            info.reason = context.error().message;
        }
        out.push_back(std::move(info));
    }
    return out;
#else
    return MakeError("not built in this build (configure with CLOUDBENCH_WITH_GL=ON)");
#endif
}

}  // namespace cb
