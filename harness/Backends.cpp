// The backend registry: which backends this build has, and how to make one.
#include "core/Backend.h"
#include "impl_cpu/BackendCpu.h"

namespace cb {

std::vector<std::string> BuiltBackends() { return {"cpu"}; }

Result<std::unique_ptr<Backend>> CreateBackend(const std::string& name, const BackendOptions& options) {
    if (name == "cpu") return std::make_unique<cpu::BackendCpu>(options.cpuThreads);
    if (name == "gl") return MakeError("gl: the OpenGL backend is not built in this build (issue 5)");
    if (name == "vk") return MakeError("vk: the Vulkan backend is not built in this build (issue 4)");
    return MakeError(name + ": unknown backend (known: cpu, gl, vk)");
}

}  // namespace cb
