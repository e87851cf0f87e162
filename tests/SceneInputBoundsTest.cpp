// Bounded input (issue 11, "Every bad input refused clearly"): scene files that are not regular files or are too
// large, JSON nested too deep, echoed text kept short and free of control bytes, and derived sizes that must not wrap.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "SceneTestUtil.h"
#include "core/Scene.h"

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
    EXPECT_EQ(LoadError("/nonexistent/scene.json"), "/nonexistent/scene.json: cannot read the file: No such file or directory");
}

}  // namespace
}  // namespace cb
