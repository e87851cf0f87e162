// Opens libcloudbench_images.so (harness/report/images/ImageModule.h) on first use:
// beside the executable (the cloudbench binary, installed or in the build
// tree), else at the path the build put it (the test and benchmark
// executables, which live in other folders of the build tree).
#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "harness/report/images/ImageModule.h"

namespace cb::images {
namespace {

Result<const Module*> Open() {
    std::vector<std::string> candidates;
    std::error_code error;
    const auto executable = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error) candidates.push_back((executable.parent_path() / kModuleFileName).string());
    candidates.push_back(CLOUDBENCH_IMAGE_MODULE_PATH);
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
