// The output folder's claim (harness/OutputFolder.h): the journal of written
// files, what the next claim removes, and what it never touches.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "harness/OutputFolder.h"
#include "harness/Session.h"

namespace cb {
namespace {
namespace fs = std::filesystem;

// A fresh folder per test; claims last as long as the process, so each test uses its own.
std::string FreshFolder(const std::string& name) {
    const std::string dir = ::testing::TempDir() + "/outputfolder-" + std::to_string(getpid()) + "-" + name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

void Touch(const std::string& path, const std::string& text = "x") {
    fs::create_directories(fs::path(path).parent_path());
    std::ofstream(path) << text;
}

// Test that the files written through WriteAtomically are journalled and listed in write order, once each.
TEST(OutputFolder, WrittenFilesListedInOrder) {
    const std::string dir = FreshFolder("listed");
    ASSERT_TRUE(ClaimOutputFolder(dir, "run"));
    ASSERT_TRUE(Session::WriteText(dir + "/results.json", "{}\n"));
    fs::create_directories(dir + "/sub");
    ASSERT_TRUE(Session::WriteText(dir + "/sub/b.txt", "b\n"));
    ASSERT_TRUE(Session::WriteText(dir + "/a.txt", "a\n"));
    ASSERT_TRUE(Session::WriteText(dir + "/results.json", "{}\n"));
    EXPECT_EQ(WrittenOutputs(dir, "results.json"), (std::vector<std::string>{"sub/b.txt", "a.txt"}));
    EXPECT_EQ(WrittenOutputs(dir).size(), 3u);
    // A file outside every claimed folder is written, not journalled.
    const std::string elsewhere = FreshFolder("elsewhere");
    ASSERT_TRUE(Session::WriteText(elsewhere + "/c.txt", "c\n"));
    EXPECT_TRUE(WrittenOutputs(elsewhere).empty());
    EXPECT_EQ(WrittenOutputs(dir).size(), 3u);
}

// Test that a failed write leaves no file in the list.
TEST(OutputFolder, FailedWriteNotListed) {
    const std::string dir = FreshFolder("failed");
    ASSERT_TRUE(ClaimOutputFolder(dir, "run"));
    EXPECT_FALSE(Session::WriteAtomically(dir + "/bad.txt", [](const std::string&) -> Status {
        return MakeError("refused");
    }));
    EXPECT_TRUE(WrittenOutputs(dir).empty());
}

// Test that the next claim of a folder removes what the previous journal of the same command lists (placed
// files and temporary names, and the folders left empty), and nothing else: not another command's outputs,
// not a file it does not list, not a name outside the folder however the journal spells it.
TEST(OutputFolder, ClaimRemovesOnlyJournalledFiles) {
    const std::string dir = FreshFolder("journal");
    const std::string outside = FreshFolder("outside") + "/keep.txt";
    Touch(outside);
    for (const char* name : {"results.json", "frame.png", "step_0001/q.npy", ".frame.partial.png", "mine.txt",
                             "step_0002/mine.npy", "step_0002/q.npy", "sweep.json"})
        Touch(dir + "/" + name);
    const std::string relativeOutside = fs::relative(outside, dir).generic_string();  // "../outputfolder-.../keep.txt"
    std::ofstream(dir + "/.cloudbench-run.files") << "+ results.json\n= results.json\n+ frame.png\n"
                                                     "+ step_0001/q.npy\n= step_0001/q.npy\n= step_0002/q.npy\n"
                                                  << "= " << relativeOutside << "\n= " << outside << "\n"
                                                  << "= step_0002/../mine.txt\n= ./mine.txt\n= mine.txt";  // cut short
    std::ofstream(dir + "/.cloudbench-sweep.files") << "= sweep.json\n";
    ASSERT_TRUE(ClaimOutputFolder(dir, "run"));
    EXPECT_FALSE(fs::exists(dir + "/results.json"));
    EXPECT_TRUE(fs::exists(dir + "/frame.png"));  // only being written: its temporary name goes, not the file
    EXPECT_FALSE(fs::exists(dir + "/.frame.partial.png"));
    EXPECT_FALSE(fs::exists(dir + "/step_0001"));  // emptied, so removed
    EXPECT_FALSE(fs::exists(dir + "/step_0002/q.npy"));
    EXPECT_TRUE(fs::exists(dir + "/step_0002/mine.npy"));
    EXPECT_TRUE(fs::exists(dir + "/mine.txt"));
    EXPECT_TRUE(fs::exists(outside));
    EXPECT_TRUE(fs::exists(dir + "/sweep.json"));
    std::ifstream journal(dir + "/.cloudbench-run.files");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(journal), {}), "");  // a new journal
}

// Test that a folder claimed by this process can be claimed again (a second MakeOutDir), and that another
// open of the lock file cannot take it while the claim lasts.
TEST(OutputFolder, ClaimIsExclusive) {
    const std::string dir = FreshFolder("exclusive");
    ASSERT_TRUE(ClaimOutputFolder(dir, "dump"));
    EXPECT_TRUE(ClaimOutputFolder(dir, "dump"));
    std::ifstream lock(dir + "/.cloudbench.lock");
    std::string line;
    std::getline(lock, line);
    EXPECT_EQ(line, std::to_string(getpid()) + " dump");
    // flock locks belong to the open file description, so a second open conflicts even in this process.
    const int fd = open((dir + "/.cloudbench.lock").c_str(), O_RDONLY | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    EXPECT_NE(flock(fd, LOCK_EX | LOCK_NB), 0);
    close(fd);
}

}  // namespace
}  // namespace cb
