#include "registry/Registry.h"

#include <cstdlib>
#include <cstring>

#include "impl_cpu/BackendCpu.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif
#if CLOUDBENCH_HAVE_GL
#include "impl_gl/BackendGL.h"
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

}  // namespace cb
