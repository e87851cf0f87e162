// Opens libcloudbench_images.so (harness/report/images/ImageModule.h) on first use,
// at the first of core/base/InstallLayout.h's places that holds it.
#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "core/base/InstallLayout.h"
#include "harness/report/images/ImageModule.h"

namespace cb::images {
namespace {

Result<const Module*> Open() {
    const std::vector<std::string> candidates = ModuleCandidates(kModuleFileName);
    std::error_code error;
    std::string tried;
    for (const std::string& path : candidates) {
        if (!std::filesystem::exists(path, error)) {
            tried += (tried.empty() ? "" : ", ") + path;
            continue;
        }
        void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!handle) return MakeError("cannot load the image module " + path + ": " + dlerror());
        auto entry = reinterpret_cast<const Module* (*)()>(dlsym(handle, "cloudbench_image_module"));
        if (!entry) return MakeError("cannot load the image module " + path + ": " + dlerror());
        const Module* module = entry();
        if (module->version != kModuleVersion)
            return MakeError("the image module " + path + " is version " + std::to_string(module->version) +
                             ", this cloudbench needs version " + std::to_string(kModuleVersion) +
                             " (reinstall cloudbench)");
        return module;  // kept open for the life of the process
    }
    return MakeError(std::string("cannot find the image module ") + kModuleFileName + " (looked for " + tried + ")");
}

}  // namespace

Result<const Module*> Load() {
    static std::once_flag once;
    static Result<const Module*> loaded = MakeError("not loaded");
    std::call_once(once, [] { loaded = Open(); });
    return loaded;
}

}  // namespace cb::images
