#include "harness/perf/Spawn.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string_view>

#include "harness/platform/OutputFolder.h"

extern char** environ;

namespace cb::perf {

Result<int> RunChild(const std::vector<std::string>& argv, const std::string& stdoutPath,
                     const std::vector<std::string>& setEnv) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::vector<char*> env;
    for (char** e = environ; e && *e; ++e) {
        const std::string_view entry(*e);
        const bool replaced = std::any_of(setEnv.begin(), setEnv.end(), [&](const std::string& s) {
            const size_t name = s.find('=') + 1;  // the length of "NAME="; 0 without '='
            return name > 0 && entry.substr(0, name) == std::string_view(s).substr(0, name);
        });
        if (!replaced) env.push_back(*e);
    }
    for (const std::string& s : setEnv) env.push_back(const_cast<char*>(s.c_str()));
    env.push_back(nullptr);
    // The log is opened here, by the path policy (no link followed inside an output folder, no FIFO), and
    // handed to the child as its standard output.
    int logFd = -1;
    if (!stdoutPath.empty()) {
        const std::filesystem::path log(stdoutPath);
        auto folder = OpenFolderForWriting(log.parent_path().string(), /*create=*/false);
        if (!folder) return std::unexpected(folder.error());
        auto opened = OpenFileAt(folder->Fd(), stdoutPath, log.filename().string(), WriteMode::Append);
        if (!opened) return std::unexpected(opened.error());
        logFd = *opened;
    }
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (logFd >= 0) posix_spawn_file_actions_adddup2(&actions, logFd, STDOUT_FILENO);
    pid_t pid = 0;
    const int error = posix_spawn(&pid, args[0], &actions, nullptr, args.data(), env.data());
    posix_spawn_file_actions_destroy(&actions);
    if (logFd >= 0) ::close(logFd);
    if (error != 0) return MakeError(argv[0] + ": cannot run: " + std::strerror(error));
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return MakeError(argv[0] + ": cannot wait: " + std::strerror(errno));
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return WEXITSTATUS(status);
}

std::string SelfPath() {
    std::error_code ec;
    const auto path = std::filesystem::read_symlink("/proc/self/exe", ec);
    return ec ? "/proc/self/exe" : path.string();
}

}  // namespace cb::perf
