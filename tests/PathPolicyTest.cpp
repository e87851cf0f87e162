// The path policy (core/base/PathPolicy.h), case by case: what a reader beneath
// a folder, a reader of a named path and a writer in a folder each do with a
// link out of the folder, a link inside it, a FIFO, a folder, a device, an
// empty file and a file too large. The commands' own readers and writers are
// run against the same cases by tests/check_path_policy.py.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "core/base/PathPolicy.h"

namespace cb {
namespace {

namespace fs = std::filesystem;

constexpr InputKind kTinyInput{"a tiny file", 8, 1};

// A folder `inside` holding the cases by name, and a file outside it that a link may lead to.
class PathPolicyTest : public ::testing::Test {
  protected:
    void SetUp() override {
        mRoot = fs::temp_directory_path() / ("cloudbench-paths-" + std::to_string(getpid()));
        fs::remove_all(mRoot);
        fs::create_directories(mRoot / "inside" / "sub");
        Put(mRoot / "outside.txt", "secret");
        Put(mRoot / "inside" / "sub" / "real.txt", "mine");
        const fs::path in = mRoot / "inside";
        fs::create_symlink(mRoot / "outside.txt", in / "link-out");
        fs::create_symlink("../outside.txt", in / "link-up");
        fs::create_symlink("sub/real.txt", in / "link-in");
        fs::create_symlink(mRoot, in / "folder-link-out");
        fs::create_symlink("/dev/zero", in / "zero");
        EXPECT_EQ(mkfifo((in / "fifo").c_str(), 0600), 0);
        fs::create_directories(in / "folder");
        Put(in / "empty", "");
        Put(in / "large", "123456789");
        Put(in / "plain", "12345678");
    }
    void TearDown() override { fs::remove_all(mRoot); }
    static void Put(const fs::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }
    std::string Inside() const { return (mRoot / "inside").string(); }
    fs::path mRoot;
};

template <typename T>
std::string PolicyError(const Result<T>& r) {
    return r ? "" : r.error().message;
}

// Test each case of a name read beneath a folder: the verdict and the whole message.
TEST_F(PathPolicyTest, ReadBeneathAFolder) {
    const std::string in = Inside();
    const std::string out = ": leads out of " + in +
                            " (a symbolic link, an absolute name or ..); cloudbench reads nothing outside the folder "
                            "it was given";
    struct Case {
        std::string name, error, text;
    };
    const Case cases[] = {
        {"plain", "", "12345678"},
        {"link-in", "", "mine"},
        {"sub/real.txt", "", "mine"},
        {"sub/../plain", "", "12345678"},
        {"empty", "", ""},
        {"link-out", in + "/link-out" + out, ""},
        {"link-up", in + "/link-up" + out, ""},
        {"folder-link-out/outside.txt", in + "/folder-link-out/outside.txt" + out, ""},
        {"../outside.txt", in + "/../outside.txt" + out, ""},
        {(mRoot / "outside.txt").string(), in + "/" + (mRoot / "outside.txt").string() + out, ""},
        {"zero", in + "/zero" + out, ""},  // /dev/zero lies outside the folder
        {"fifo", in + "/fifo: not a regular file (a FIFO)", ""},
        {"folder", in + "/folder: not a regular file (a folder)", ""},
        {"large", in + "/large: 9 bytes, more than the 8 bytes a tiny file may have", ""},
        {"missing", in + "/missing: cannot read the file: No such file or directory", ""},
    };
    for (const Case& c : cases) {
        const auto start = std::chrono::steady_clock::now();
        const Result<std::string> text = ReadInputBeneath(in, c.name, kTinyInput);
        EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2)) << c.name;
        EXPECT_EQ(PolicyError(text), c.error) << c.name;
        if (c.error.empty() && text) EXPECT_EQ(*text, c.text) << c.name;
    }
}

// Test that a path the user names is taken as named: links followed, a FIFO, a device and a folder refused.
TEST_F(PathPolicyTest, ReadANamedPath) {
    const std::string in = Inside();
    EXPECT_EQ(*ReadInputFile(in + "/link-out", kTinyInput), "secret");
    EXPECT_EQ(*ReadInputFile(in + "/link-in", kTinyInput), "mine");
    EXPECT_EQ(PolicyError(ReadInputFile(in + "/zero", kTinyInput)), in + "/zero: not a regular file (a device)");
    EXPECT_EQ(PolicyError(ReadInputFile(in + "/fifo", kTinyInput)), in + "/fifo: not a regular file (a FIFO)");
    EXPECT_EQ(PolicyError(ReadInputFile(in + "/folder", kTinyInput)), in + "/folder: not a regular file (a folder)");
    EXPECT_EQ(PolicyError(ReadInputFile(in + "/large", kTinyInput)),
              in + "/large: 9 bytes, more than the 8 bytes a tiny file may have");
    EXPECT_EQ(*ReadInputFile(in + "/empty", kTinyInput), "");
}

// Test each case of a name opened for writing in a folder, in every mode: no link is followed, in or out; only a
// regular file is written; the file outside is never touched.
TEST_F(PathPolicyTest, WriteInAFolder) {
    const std::string in = Inside();
    const int folder = OpenNamedFolder(in);
    ASSERT_GE(folder, 0);
    const std::string link = ": is a symbolic link; cloudbench does not write through links (remove it)";
    auto notFile = [](const std::string& kind) {
        return ": not a regular file (" + kind + "); cloudbench writes only regular files (remove it)";
    };
    struct Case {
        std::string name;
        WriteMode mode;
        std::string error;  // after "IN/NAME"; "" when it opens
    };
    const Case cases[] = {
        {"plain", WriteMode::Append, ""},
        {"plain", WriteMode::InPlace, ""},
        {"empty", WriteMode::Append, ""},
        {"new", WriteMode::Append, ""},
        {"link-out", WriteMode::Append, link},
        {"link-out", WriteMode::InPlace, link},
        {"link-out", WriteMode::CreateNew, link},
        {"link-in", WriteMode::Append, link},
        {"zero", WriteMode::Append, link},
        {"fifo", WriteMode::Append, notFile("a FIFO")},
        {"fifo", WriteMode::InPlace, notFile("a FIFO")},
        {"folder", WriteMode::Append, notFile("a folder")},
        {"plain", WriteMode::CreateNew, ": cannot write: File exists"},
    };
    for (const Case& c : cases) {
        const auto start = std::chrono::steady_clock::now();
        const std::string shown = in + "/" + c.name;
        Result<int> fd = OpenFileAt(folder, shown, c.name, c.mode);
        EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2)) << c.name;
        EXPECT_EQ(PolicyError(fd), c.error.empty() ? "" : shown + c.error) << c.name << " mode " << int(c.mode);
        if (fd) close(*fd);
    }
    close(folder);
    std::ifstream outside(mRoot / "outside.txt");
    std::string text((std::istreambuf_iterator<char>(outside)), {});
    EXPECT_EQ(text, "secret");
}

// Test that nothing is renamed over what is not a regular file, and a missing or regular name passes.
TEST_F(PathPolicyTest, ReplaceOnlyRegularFiles) {
    const std::string in = Inside();
    const int folder = OpenNamedFolder(in);
    ASSERT_GE(folder, 0);
    auto error = [&](const std::string& name) {
        const Status s = RefuseNonFileAt(folder, in + "/" + name, name);
        return s ? std::string() : s.error().message;
    };
    EXPECT_EQ(error("plain"), "");
    EXPECT_EQ(error("missing"), "");
    EXPECT_EQ(error("link-in"), in + "/link-in: is a symbolic link; cloudbench does not write through links (remove it)");
    EXPECT_EQ(error("fifo"), in + "/fifo: not a regular file (a FIFO); cloudbench replaces only regular files (remove it)");
    EXPECT_EQ(error("folder"),
              in + "/folder: not a regular file (a folder); cloudbench replaces only regular files (remove it)");
    close(folder);
}

// Test that a named file appended to is created with its folders, and a link or FIFO at its name refused.
TEST_F(PathPolicyTest, AppendToANamedFile) {
    const std::string in = Inside();
    Result<int> made = OpenAppendFile(in + "/new/folders/history.jsonl");
    ASSERT_TRUE(made) << made.error().message;
    close(*made);
    EXPECT_TRUE(fs::is_regular_file(in + "/new/folders/history.jsonl"));
    EXPECT_EQ(PolicyError(OpenAppendFile(in + "/link-out")),
              in + "/link-out: is a symbolic link; cloudbench does not write through links (remove it)");
    EXPECT_EQ(PolicyError(OpenAppendFile(in + "/fifo")),
              in + "/fifo: not a regular file (a FIFO); cloudbench writes only regular files (remove it)");
}

}  // namespace
}  // namespace cb
