// Scene loading: JSON text -> overrides -> validation -> Scene. Every check
// reports into one list of "label: field: reason" lines, so a user sees all
// problems of a file at once. The format is documented in docs/scenes.md; the
// document is built by core/JsonDom, checked by core/SceneValidator and read
// section by section by core/SceneReaders.
#include "core/Scene.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <optional>

#include "core/JsonDom.h"
#include "core/SceneReaders.h"
#include "core/SceneValidator.h"

namespace cb {
namespace {

using scene_io::Describe;
using scene_io::Json;
using scene_io::JsonDom;
using scene_io::Validator;

Result<Scene> ParseSceneChecked(const std::string& text, const std::string& label,
                                const std::vector<SceneOverride>& overrides) {
    Validator check(label);
    JsonDom dom = scene_io::ParseJsonDom(text);
    if (dom.failure) {
        check.FailWhole(scene_io::DescribeParseFailure(text, *dom.failure));
        return MakeError(check.Message());
    }
    Json& root = dom.root;
    for (const std::string& duplicate : dom.duplicates) check.Fail(duplicate, "duplicate field");
    if (!root.is_object()) {
        check.FailWhole("expected a JSON object at the top level, got " + Describe(root));
        return MakeError(check.Message());
    }
    for (const SceneOverride& item : overrides) scene_io::ApplyOverride(root, item, check);

    Scene scene;
    scene_io::ReadScene(root, label, check, scene);
    if (check.ErrorCount() > 0) return MakeError(check.Message());

    // One pair means "the same shift for every slice"; expanded only now that nz is known to be sane.
    if (scene.ca.windShift.size() == 1 && scene.grid.size.nz > 1)
        scene.ca.windShift.assign(scene.grid.size.nz, scene.ca.windShift[0]);
    return scene;
}

}  // namespace

double SunSettings::ElevationAt(uint32_t step) const {
    if (path.empty()) return elevationDeg + elevationSpeedDeg * double(step);
    if (step <= path.front().step) return path.front().elevationDeg;
    if (step >= path.back().step) return path.back().elevationDeg;
    size_t b = 1;
    while (path[b].step < step) ++b;
    const SunKeyframe &lo = path[b - 1], &hi = path[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return lo.elevationDeg + (hi.elevationDeg - lo.elevationDeg) * w;
}

double SunSettings::AzimuthAt(uint32_t step) const {
    if (path.empty()) return azimuthDeg + azimuthSpeedDeg * double(step);
    if (step <= path.front().step) return path.front().azimuthDeg;
    if (step >= path.back().step) return path.back().azimuthDeg;
    size_t b = 1;
    while (path[b].step < step) ++b;
    const SunKeyframe &lo = path[b - 1], &hi = path[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return lo.azimuthDeg + (hi.azimuthDeg - lo.azimuthDeg) * w;
}

Result<Scene> ParseScene(const std::string& text, const std::string& label,
                         const std::vector<SceneOverride>& overrides) {
    try {
        return ParseSceneChecked(text, label, overrides);
    } catch (const std::exception& e) {
        return MakeError(label + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(label + ": internal error while reading the scene");
    }
}

namespace {

// Largest scene file read; the shipped scenes take a few KiB.
constexpr uint64_t kMaxSceneBytes = uint64_t(16) << 20;

// What a path that is not a regular file is, for "PATH: not a regular file (...)".
std::string KindOf(std::filesystem::file_type type) {
    using std::filesystem::file_type;
    switch (type) {
        case file_type::fifo:
            return "a FIFO";
        case file_type::block:
        case file_type::character:
            return "a device";
        case file_type::directory:
            return "a folder";
        case file_type::socket:
            return "a socket";
        default:
            return "not a file";
    }
}

std::string TooLarge(const std::string& path, uint64_t bytes) {
    return path + ": " + std::to_string(bytes) + " bytes, more than the " + std::to_string(kMaxSceneBytes >> 20) +
           " MiB a scene may have";
}

// The whole text of the scene file at `path`, or why it cannot be a scene: only regular files of at most
// kMaxSceneBytes are read, so /dev/zero cannot fill memory and a FIFO cannot block.
Result<std::string> ReadSceneText(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    // A path that cannot be inspected is left to open(), which names the reason (missing, no permission).
    if (!ec && status.type() != std::filesystem::file_type::regular)
        return MakeError(path + ": not a regular file (" + KindOf(status.type()) + ")");

    // O_NONBLOCK: should the path become a FIFO after the check, opening it still returns at once.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return MakeError(path + ": cannot read the file: " + std::strerror(errno));
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat info {};
    if (::fstat(fd, &info) != 0) return MakeError(path + ": cannot read the file: " + std::strerror(errno));
    if (!S_ISREG(info.st_mode)) {
        const auto type = S_ISFIFO(info.st_mode)                           ? std::filesystem::file_type::fifo
                          : S_ISCHR(info.st_mode) || S_ISBLK(info.st_mode) ? std::filesystem::file_type::character
                          : S_ISDIR(info.st_mode)                          ? std::filesystem::file_type::directory
                                                                           : std::filesystem::file_type::unknown;
        return MakeError(path + ": not a regular file (" + KindOf(type) + ")");
    }
    if (uint64_t(info.st_size) > kMaxSceneBytes) return MakeError(TooLarge(path, uint64_t(info.st_size)));

    // Read at most one byte past the limit, in case the file grew since fstat.
    std::string text(size_t(info.st_size), '\0');
    size_t used = 0;
    for (;;) {
        if (used == text.size()) text.resize(std::min<size_t>(kMaxSceneBytes + 1, text.size() + (1 << 16)));
        if (used == text.size()) break;
        const ssize_t n = ::read(fd, text.data() + used, text.size() - used);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return MakeError(path + ": cannot read the file: " + std::strerror(errno));
        if (n == 0) break;
        used += size_t(n);
    }
    if (used > kMaxSceneBytes) return MakeError(TooLarge(path, used));
    text.resize(used);
    return text;
}

}  // namespace

Result<Scene> LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides) {
    try {
        Result<std::string> text = ReadSceneText(path);
        if (!text) return MakeError(text.error().message);
        Result<Scene> scene = ParseScene(*text, path, overrides);
        if (scene) scene->path = path;
        return scene;
    } catch (const std::exception& e) {
        return MakeError(path + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(path + ": internal error while reading the scene");
    }
}

}  // namespace cb
