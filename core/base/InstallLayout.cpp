#include "core/base/InstallLayout.h"

#include <cstdlib>
#include <filesystem>

namespace cb {
namespace {

namespace fs = std::filesystem;

// The folder of this executable, or "" when /proc/self/exe cannot be read.
fs::path ExecutableFolder() {
    std::error_code error;
    const fs::path executable = fs::read_symlink("/proc/self/exe", error);
    return error ? fs::path() : executable.parent_path();
}

// `relative` under the install prefix this executable would have (its folder's parent), or "" without one.
fs::path Installed(const char* relative) {
    const fs::path folder = ExecutableFolder();
    return folder.empty() ? fs::path() : folder.parent_path() / relative;
}

// The installed folder `relative` when this executable has one, else the build tree's `buildTree`.
std::string InstalledFolderOr(const char* relative, const char* buildTree) {
    std::error_code error;
    if (const fs::path installed = Installed(relative); !installed.empty() && fs::is_directory(installed, error))
        return installed.string();
    return buildTree;
}

}  // namespace

std::string SceneFolder() {
    if (const char* env = std::getenv("CLOUDBENCH_SCENES")) return env;
    return InstalledFolderOr(CLOUDBENCH_INSTALL_SCENES_DIR, CLOUDBENCH_SCENES_DIR);
}

std::string ToolsFolder() { return InstalledFolderOr(CLOUDBENCH_INSTALL_TOOLS_DIR, CLOUDBENCH_TOOLS_DIR); }

std::vector<std::string> ModuleCandidates(std::string_view fileName) {
    std::vector<std::string> candidates;
    if (const fs::path folder = ExecutableFolder(); !folder.empty()) candidates.push_back((folder / fileName).string());
    if (const fs::path installed = Installed(CLOUDBENCH_INSTALL_MODULE_DIR); !installed.empty())
        candidates.push_back((installed / fileName).string());
    candidates.push_back((fs::path(CLOUDBENCH_BUILD_MODULE_DIR) / fileName).string());
    return candidates;
}

}  // namespace cb
