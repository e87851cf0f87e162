// The backend registry: which backends this build has and how to make one by
// name. The one library that
// knows the concrete backends; the harness and the tests go through it and
// include no backend's own header for it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/Backend.h"
#include "core/Error.h"
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

}  // namespace cb
