// Bounded input, so that every bad input is refused clearly: scene files that are not regular files or are too
// large, JSON nested too deep, echoed text kept short and free of control bytes, and derived sizes that must not wrap.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "SceneTestUtil.h"
#include "core/base/ProcessMemory.h"
#include "core/math/Grid.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"

namespace cb {
namespace {

using test::ErrorOf;
using test::HasLine;
using test::Parsed;
using test::SplitLines;

namespace fs = std::filesystem;

// A fresh folder of this test process, removed at the end.
class TempFolder {
  public:
    TempFolder() : mPath(fs::temp_directory_path() / ("cloudbench-inputbounds-" + std::to_string(getpid()))) {
        fs::remove_all(mPath);
        fs::create_directories(mPath);
    }
    ~TempFolder() {
        std::error_code ec;
        fs::remove_all(mPath, ec);
    }
    const fs::path& Path() const { return mPath; }

  private:
    fs::path mPath;
};

std::string LoadError(const std::string& path) {
    Result<Scene> scene = LoadScene(path);
    if (scene) {
        ADD_FAILURE() << path << " was accepted";
        return "";
    }
    return scene.error().message;
}

// Test that a FIFO is refused without being opened (opening one with no writer would block forever).
TEST(SceneInputBoundsTest, FifoRefused) {
    TempFolder folder;
    const std::string path = (folder.Path() / "scene.json").string();
    ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
    EXPECT_EQ(LoadError(path), path + ": not a regular file (a FIFO)");
}

// Test that a device is refused rather than read until memory runs out.
TEST(SceneInputBoundsTest, DeviceRefused) {
    EXPECT_EQ(LoadError("/dev/zero"), "/dev/zero: not a regular file (a device)");
}

// Test that a folder is refused by kind.
TEST(SceneInputBoundsTest, FolderRefused) {
    TempFolder folder;
    const std::string path = folder.Path().string();
    EXPECT_EQ(LoadError(path), path + ": not a regular file (a folder)");
}

// Test that a file over 16 MiB is refused with its size, and one of exactly 16 MiB is read.
TEST(SceneInputBoundsTest, LargeFileRefused) {
    TempFolder folder;
    const std::string path = (folder.Path() / "big.json").string();
    {
        std::ofstream file(path);
        file << "{}" << std::string(20971520 - 2, ' ');
    }
    EXPECT_EQ(LoadError(path), path + ": 20971520 bytes, more than the 16 MiB a scene may have");

    fs::resize_file(path, 16 << 20);  // at the limit: read, then refused for what it holds, not for its size
    EXPECT_EQ(LoadError(path), path + ": grid.size: required field is missing");
}

// Test that a missing file still names the reason.
TEST(SceneInputBoundsTest, MissingFileNamesReason) {
    EXPECT_EQ(LoadError("/nonexistent/scene.json"),
              "/nonexistent/scene.json: cannot read the file: No such file or directory");
}

// Test that 100,000 nested arrays are refused at the 65th level, where the parser stops (time is not
// asserted here; the bad-input set's timeouts bound it).
TEST(SceneInputBoundsTest, DeepNestingRefused) {
    const std::string text = R"({"grid": )" + std::string(100000, '[') + std::string(100000, ']') + "}";
    const std::string message = ErrorOf(text);
    // Level 1 is the top object, so the 64th '[' (column 10 + 63) opens level 65.
    EXPECT_EQ(message, "test.json: line 1, column 73: nested deeper than 64 levels");

    // 64 levels are read (and then refused for what they hold, not for their depth).
    const std::string deepest = R"({"grid": )" + std::string(63, '[') + std::string(63, ']') + "}";
    EXPECT_EQ(ErrorOf(deepest).find("nested deeper"), std::string::npos);

    // Objects count too, and the same bound holds for a --set value.
    std::string objects;
    for (int i = 0; i < 70; ++i) objects += R"({"a": )";
    objects += '1';
    objects.append(70, '}');
    EXPECT_EQ(ErrorOf(objects), "test.json: line 1, column 385: nested deeper than 64 levels");
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}})", {{"ca.seed", std::string(100, '[')}}),
                        "test.json: ca.seed: nested deeper than 64 levels (set on the command line)"));
}

// Test that a duplicate key deep in the document is still named by its whole path.
TEST(SceneInputBoundsTest, DuplicateKeyPathKept) {
    EXPECT_TRUE(HasLine(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "x": [0, {"a": 1, "a": 2}]})"),
                        "test.json: x[1].a: duplicate field"));
}

// Test that a key with control bytes is shown escaped in its field path, never as raw bytes.
TEST(SceneInputBoundsTest, ControlBytesInKeyEscaped) {
    const std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "a\u001b[31m\u0007": 1})");
    EXPECT_EQ(message, "test.json: a\\u001b[31m\\u0007: unknown field");
    EXPECT_EQ(message.find('\x1b'), std::string::npos);
    EXPECT_EQ(message.find('\x07'), std::string::npos);
}

// Test that a string value with control bytes is shown escaped, inside arrays too.
TEST(SceneInputBoundsTest, ControlBytesInValueEscaped) {
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": "\u001b[2J"})"),
              R"(test.json: steps: expected an integer, got "\u001b[2J")");
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": ["\u001b\u009b"]})"),
              R"(test.json: steps: expected an integer, got ["\u001b\u009b"])");
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stages": ["region", "x\u0007"]})").find('\x07'),
              std::string::npos);
}

// Test that a 50 MB key is shown cut to 60 characters, with no "did you mean" computed on it (the edit
// distance to every field name took 9 s on such a key; time is not asserted here, the bad-input set's
// timeouts bound it).
TEST(SceneInputBoundsTest, HugeKeyCutShort) {
    const std::string key(50'000'000, 'k');
    const std::string message = ErrorOf(R"({"grid": {"size": [8, 4, 6]}, ")" + key + R"(": 1})");
    EXPECT_EQ(message, "test.json: " + std::string(57, 'k') + "...: unknown field");

    // A long value is cut the same way.
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "steps": ")" + key + R"("})"),
              "test.json: steps: expected an integer, got \"" + std::string(57, 'k') + "...\"");
    // Near misses of normal length still get their suggestion.
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 4, 6]}, "stpes": 1})"),
              R"(test.json: stpes: unknown field (did you mean "steps"?))");
}

// Test that a tile or band whose count would wrap 32 bits (CeilDiv adds edge - 1) is refused at the grid's edge.
TEST(SceneInputBoundsTest, TileAndBandBoundedByGrid) {
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [16, 8, 6]}, "density": {"tile": 4294967295}})"),
              "test.json: density.tile: must be at most 4294967280 (2^32 - the grid's longer horizontal edge 16, so "
              "the count fits 32 bits), got 4294967295");
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [16, 8, 6]}, "density": {"band": 4294967295}})"),
              "test.json: density.band: must be at most 4294967290 (2^32 - the grid's height 6, so the count fits 32 "
              "bits), got 4294967295");
    // At the bound, and far past the grid's edge but below it, the value is kept: one tile, one band.
    const Scene scene = Parsed(R"({"grid": {"size": [16, 8, 6]}, "density": {"tile": 4294967280, "band": 1000}})");
    EXPECT_EQ(scene.density.tile, 4294967280u);
    EXPECT_EQ(scene.density.band, 1000u);
    const uint32_t tile = scene.density.tile;
    EXPECT_EQ((16u + tile - 1) / tile, 1u);
}

// Test that CeilDiv is exact up to the top of uint32: (a + b - 1) / b wrapped there and gave 0.
TEST(SceneInputBoundsTest, CeilDivDoesNotWrap) {
    constexpr uint32_t kMax = 4294967295u;
    EXPECT_EQ(CeilDiv(kMax, kMax), 1u);
    EXPECT_EQ(CeilDiv(1, kMax), 1u);
    EXPECT_EQ(CeilDiv(kMax, 2), 2147483648u);
    EXPECT_EQ(CeilDiv(kMax - 1, 2), 2147483647u);
    EXPECT_EQ(CeilDiv(0, 7), 0u);
    EXPECT_EQ(CeilDiv(64, 64), 1u);
    EXPECT_EQ(CeilDiv(65, 64), 2u);
}

// Test that optical depths formed from in-range fields are checked where they are formed: sigma 1e28 and a voxel of
// 1 km give 1e31 per cell (T was NaN in single precision), and a grazing sun divides sigma h by ~1e-42.
TEST(SceneInputBoundsTest, DerivedOpticalDepthBounded) {
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 8, 8], "voxel_size": 1000}, "shade": {"sigma": 1e28}})"),
              "test.json: shade.sigma: sigma * grid.voxel_size * shade.resolution (the optical depth of one cell) "
              "must be at most 1e+30, got 1e+31");
    EXPECT_NE(ErrorOf(R"({"grid": {"size": [8, 8, 8]}, "sun": {"elevation_deg": 1e-40}})")
                  .find("test.json: shade.sigma: sigma * grid.voxel_size / sin(sun.elevation_deg)"),
              std::string::npos);
    EXPECT_EQ(ErrorOf(R"({"grid": {"size": [8, 8, 8], "voxel_size": 1e300}})"),
              "test.json: grid.voxel_size: must be in (0, 1e+30], got 1e+300");
    // At the bounds the scene is kept.
    const Scene scene = Parsed(R"({"grid": {"size": [8, 8, 8], "voxel_size": 1e30}, "shade": {"sigma": 0}})");
    EXPECT_EQ(scene.grid.voxelSize, 1e30);
}

// Test that an object --set creates is the command line's: an unknown section it names says so.
TEST(SceneInputBoundsTest, SetCreatedSectionMarkedAsCommandLine) {
    auto scene = ParseScene(R"({"grid": {"size": [8, 8, 8]}})", "test.json", {{"foo.bar", "1"}});
    ASSERT_FALSE(scene);
    EXPECT_EQ(scene.error().message, "test.json: foo: unknown field (set on the command line)");
}

// Test that the memory limit counts RLIMIT_AS: in a child under a limit of its VmSize + 256 MiB, the fixed limit is
// RLIMIT_AS itself and what is still available is at most the 256 MiB left.
TEST(SceneInputBoundsTest, ProcessMemoryCountsAddressSpaceLimit) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        std::ifstream status("/proc/self/status");
        std::string line;
        uint64_t vmKb = 0;
        while (std::getline(status, line))
            if (line.starts_with("VmSize:")) vmKb = std::stoull(line.substr(7));
        const uint64_t limit = vmKb * 1024 + (uint64_t(256) << 20);
        const rlimit r{limit, limit};
        if (vmKb == 0 || setrlimit(RLIMIT_AS, &r) != 0) _exit(2);
        const std::optional<MemoryFigure> fixed = ProcessMemoryLimit();
        const std::optional<MemoryFigure> now = ProcessAvailableMemory();
        if (!fixed || fixed->bytes != limit || fixed->source != "RLIMIT_AS") _exit(3);
        if (!now || now->bytes > (uint64_t(256) << 20)) _exit(4);
        _exit(0);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0) << "2: no VmSize or setrlimit failed, 3: fixed limit, 4: available now";
}

}  // namespace
}  // namespace cb
