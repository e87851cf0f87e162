// The output folder's claim (harness/platform/OutputFolder.h): the journal of written
// files, what the next claim removes, and what it never touches; and that no
// name cloudbench creates, replaces, locks or removes is followed when it is a
// symbolic link.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/base/Npy.h"
#include "harness/platform/OutputFolder.h"
#include "harness/run/Session.h"

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
    EXPECT_FALSE(Session::WriteAtomically(dir + "/bad.txt", [](const Session::TemporaryFile&) -> Status {
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

// What is outside the output folder: a file a link may point to, in a folder of its own.
struct Victim {
    std::string folder, file;
    explicit Victim(const std::string& name) : folder(FreshFolder("victim-" + name)), file(folder + "/victim.txt") {
        Touch(file, "the victim's bytes\n");
    }
    std::string Contents() const {
        std::ifstream in(file, std::ios::binary);
        return std::string(std::istreambuf_iterator<char>(in), {});
    }
    // The victim file untouched and no other file in its folder.
    void ExpectUntouched() const {
        EXPECT_EQ(Contents(), "the victim's bytes\n");
        size_t entries = 0;
        for (const auto& entry : fs::directory_iterator(folder)) {
            (void)entry;
            ++entries;
        }
        EXPECT_EQ(entries, 1u) << "a file appeared in " << folder;
    }
};

std::string LinkMessage(const std::string& shown) {
    return shown + ": is a symbolic link; cloudbench does not write through links (remove it)";
}

// Test that a link planted at the lock or at the journal makes the claim fail naming it, and that the link's
// target is neither truncated nor written.
TEST(OutputFolder, ClaimRefusesLinkedLockAndJournal) {
    for (const std::string name : {".cloudbench.lock", ".cloudbench-run.files"}) {
        const std::string dir = FreshFolder("linked" + name);
        const Victim victim("claim" + name);
        fs::create_symlink(victim.file, dir + "/" + name);
        const Status claimed = ClaimOutputFolder(dir, "run");
        ASSERT_FALSE(claimed) << name;
        EXPECT_EQ(claimed.error().message, LinkMessage(dir + "/" + name));
        victim.ExpectUntouched();
        EXPECT_TRUE(fs::is_symlink(dir + "/" + name));
    }
}

// Test that a write refuses a link at the file's name and at its temporary name, leaving the target untouched,
// and that a stale temporary file (a regular file a killed write left) is replaced.
TEST(OutputFolder, WriteRefusesLinks) {
    const std::string dir = FreshFolder("write-links");
    ASSERT_TRUE(ClaimOutputFolder(dir, "run"));
    for (const std::string name : {"results.json", ".results.partial.json"}) {
        const Victim victim("write" + name);
        fs::create_symlink(victim.file, dir + "/" + name);
        const Status written = Session::WriteText(dir + "/results.json", "{}\n");
        ASSERT_FALSE(written) << name;
        EXPECT_EQ(written.error().message, LinkMessage(dir + "/" + name));
        victim.ExpectUntouched();
        fs::remove(dir + "/" + name);
    }
    Touch(dir + "/.results.partial.json", "left by a killed run");
    ASSERT_TRUE(Session::WriteText(dir + "/results.json", "{}\n"));
    EXPECT_FALSE(fs::exists(dir + "/.results.partial.json"));
}

// Test that a subfolder (dump's step_tttt) that is a link is refused when it is created and when a file is
// written in it, so nothing appears in the folder it points to.
TEST(OutputFolder, SubfolderLinkRefused) {
    const std::string dir = FreshFolder("subfolder-link");
    ASSERT_TRUE(ClaimOutputFolder(dir, "dump"));
    const Victim victim("subfolder");
    fs::create_directory_symlink(victim.folder, dir + "/step_0000");
    const Status made = MakeFolder(dir + "/step_0000");
    ASSERT_FALSE(made);
    EXPECT_EQ(made.error().message, LinkMessage(dir + "/step_0000"));
    const Status written = Session::WriteText(dir + "/step_0000/q.txt", "q\n");
    ASSERT_FALSE(written);
    EXPECT_EQ(written.error().message, LinkMessage(dir + "/step_0000"));
    victim.ExpectUntouched();
    // A real subfolder is created one name at a time, and written in.
    ASSERT_TRUE(MakeFolder(dir + "/step_0001/inner"));
    EXPECT_TRUE(Session::WriteText(dir + "/step_0001/inner/q.txt", "q\n"));
}

// Test that the library writers' name (/proc/self/fd/N) writes the temporary file WriteAtomically created,
// even when a link to another file has taken the temporary name since, and that the write is then refused.
TEST(OutputFolder, WriterNameCannotBeRedirected) {
    const std::string dir = FreshFolder("redirect");
    ASSERT_TRUE(ClaimOutputFolder(dir, "run"));
    const Victim victim("redirect");
    const Status written = Session::WriteAtomically(dir + "/frame.png", [&](const Session::TemporaryFile& temp) {
        fs::remove(dir + "/.frame.partial.png");
        fs::create_symlink(victim.file, dir + "/.frame.partial.png");
        std::ofstream(temp.path, std::ios::binary) << "image bytes";  // by name, as OpenImageIO opens it
        return Status{};
    });
    victim.ExpectUntouched();
    ASSERT_FALSE(written);
    EXPECT_NE(written.error().message.find(dir + "/frame.png: "), std::string::npos) << written.error().message;
    EXPECT_FALSE(fs::exists(dir + "/frame.png"));
}

// Test that WriteNpy by path does not write through a link at the path (O_NOFOLLOW).
TEST(OutputFolder, WriteNpyRefusesLink) {
    const std::string dir = FreshFolder("npy-link");
    const Victim victim("npy");
    fs::create_symlink(victim.file, dir + "/a.npy");
    const uint64_t shape[1] = {2};
    const std::byte data[2] = {std::byte{1}, std::byte{2}};
    EXPECT_FALSE(WriteNpy(dir + "/a.npy", NpyType::U8, shape, data));
    victim.ExpectUntouched();
}

// Test that the claim refuses to remove a file the journal lists when the name, or a folder on the way to it,
// is now a link, and removes nothing through it.
TEST(OutputFolder, ClaimRefusesLinksInTheJournal) {
    {
        const std::string dir = FreshFolder("journal-file-link");
        const Victim victim("journal-file");
        fs::create_symlink(victim.file, dir + "/results.json");
        std::ofstream(dir + "/.cloudbench-run.files") << "+ results.json\n= results.json\n";
        const Status claimed = ClaimOutputFolder(dir, "run");
        ASSERT_FALSE(claimed);
        EXPECT_EQ(claimed.error().message, LinkMessage(dir + "/results.json"));
        victim.ExpectUntouched();
    }
    {
        const std::string dir = FreshFolder("journal-folder-link");
        const Victim victim("journal-folder");
        fs::rename(victim.file, victim.folder + "/q.npy");  // the file the journal names, seen through the link
        Touch(victim.folder + "/victim.txt", "the victim's bytes\n");
        fs::create_directory_symlink(victim.folder, dir + "/step_0000");
        std::ofstream(dir + "/.cloudbench-dump.files") << "+ step_0000/q.npy\n= step_0000/q.npy\n";
        const Status claimed = ClaimOutputFolder(dir, "dump");
        ASSERT_FALSE(claimed);
        EXPECT_EQ(claimed.error().message, LinkMessage(dir + "/step_0000"));
        EXPECT_TRUE(fs::exists(victim.folder + "/q.npy"));
        EXPECT_EQ(victim.Contents(), "the victim's bytes\n");
    }
}

// Test that a journal entry naming a folder (the journal lists only files) does not block the claim: the
// folder and what it holds stay, and the journal is emptied, so later claims go on.
TEST(OutputFolder, JournalNamingAFolderIsSkipped) {
    const std::string dir = FreshFolder("journal-folder");
    Touch(dir + "/results.json/inside.txt", "kept");
    Touch(dir + "/frame.png");
    std::ofstream(dir + "/.cloudbench-run.files") << "= results.json\n= frame.png\n+ .partial\n";
    ::testing::internal::CaptureStderr();
    const Status claimed = ClaimOutputFolder(dir, "run");
    const std::string warning = ::testing::internal::GetCapturedStderr();
    ASSERT_TRUE(claimed) << claimed.error().message;
    EXPECT_NE(warning.find(dir + "/results.json: a folder where the previous run wrote a file; left in place"),
              std::string::npos)
        << warning;
    EXPECT_TRUE(fs::exists(dir + "/results.json/inside.txt"));
    EXPECT_FALSE(fs::exists(dir + "/frame.png"));
    std::ifstream journal(dir + "/.cloudbench-run.files");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(journal), {}), "");
}

// Test that the output folder itself may be a link, or lie below one (the user named it): the claim and the
// files land in the folder it points to.
TEST(OutputFolder, NamedFolderLinkFollowed) {
    const std::string real = FreshFolder("followed-real");
    const std::string link = FreshFolder("followed-link-parent") + "/out";
    fs::create_directory_symlink(real, link);
    ASSERT_TRUE(ClaimOutputFolder(link, "run"));
    ASSERT_TRUE(Session::WriteText(link + "/results.json", "{}\n"));
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(real + "/results.json")));
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(real + "/.cloudbench.lock")));
    EXPECT_EQ(WrittenOutputs(link), (std::vector<std::string>{"results.json"}));
}

// Test a file the user names outside every claimed folder (report -o FILE): a link in its folder's path is
// followed, a link at its own name or its temporary name is refused.
TEST(OutputFolder, NamedFileLinks) {
    const std::string real = FreshFolder("named-real");
    const std::string parent = FreshFolder("named-parent");
    fs::create_directory_symlink(real, parent + "/via");
    ASSERT_TRUE(Session::WriteText(parent + "/via/report.html", "<p>\n"));
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(real + "/report.html")));
    for (const std::string name : {"report.html", ".report.partial.html"}) {
        const Victim victim("named" + name);
        fs::remove(real + "/report.html");
        fs::create_symlink(victim.file, real + "/" + name);
        const Status written = Session::WriteText(parent + "/via/report.html", "<p>\n");
        ASSERT_FALSE(written) << name;
        EXPECT_EQ(written.error().message, LinkMessage(parent + "/via/" + name));
        victim.ExpectUntouched();
        fs::remove(real + "/" + name);
    }
}

// Test that RemoveTreeAt removes a folder and the links inside it as names, never what they point to, and
// refuses a link at the name it is given.
TEST(OutputFolder, RemoveTreeDoesNotFollowLinks) {
    const std::string dir = FreshFolder("tree");
    const Victim victim("tree");
    Touch(dir + "/state/a.npy");
    fs::create_symlink(victim.file, dir + "/state/file-link");
    fs::create_directory_symlink(victim.folder, dir + "/state/folder-link");
    fs::create_directory_symlink(victim.folder, dir + "/top-link");
    auto folder = OpenFolderForWriting(dir, false);
    ASSERT_TRUE(folder);
    ASSERT_TRUE(RemoveTreeAt(*folder, "state"));
    EXPECT_FALSE(fs::exists(fs::symlink_status(dir + "/state")));
    const Status refused = RemoveTreeAt(*folder, "top-link");
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().message, LinkMessage(dir + "/top-link"));
    victim.ExpectUntouched();
}

}  // namespace
}  // namespace cb
