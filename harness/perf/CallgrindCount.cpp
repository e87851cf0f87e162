#include "harness/perf/CallgrindCount.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/base/CallgrindRequests.h"
#include "core/base/PathPolicy.h"

extern char** environ;

namespace cb {
namespace {

namespace fs = std::filesystem;

// The first executable `name` on PATH; "" when there is none.
std::string FindOnPath(const std::string& name) {
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "");
    for (std::string dir; std::getline(dirs, dir, ':');) {
        const std::string candidate = (dir.empty() ? "." : dir) + "/" + name;
        if (access(candidate.c_str(), X_OK) == 0 && !fs::is_directory(candidate)) return candidate;
    }
    return "";
}

// What valgrind and the counting child wrote into the temporary folder: "" when it is not there.
std::string ReadFile(const std::string& path) { return ReadInputFile(path, kToolOutputInput).value_or(""); }

// The last `lines` lines of `text`.
std::string Tail(const std::string& text, int lines) {
    size_t from = text.size();
    if (from > 0 && text[from - 1] == '\n') --from;
    while (lines-- > 0 && from > 0) {
        const size_t newline = text.rfind('\n', from - 1);
        if (newline == std::string::npos) return text;
        from = newline;
    }
    return from < text.size() && text[from] == '\n' ? text.substr(from + 1) : text.substr(from);
}

// A temporary folder that is removed with everything in it.
class TempFolder {
  public:
    static Result<TempFolder> Create() {
        const char* tmp = std::getenv("TMPDIR");
        std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/cloudbench-count-XXXXXX";
        if (!mkdtemp(pattern.data()))
            return MakeError(pattern + ": cannot create a temporary folder: " + std::strerror(errno));
        return TempFolder(pattern);
    }
    TempFolder(TempFolder&& other) noexcept : mPath(std::exchange(other.mPath, "")) {}
    ~TempFolder() {
        std::error_code ignored;
        if (!mPath.empty()) fs::remove_all(mPath, ignored);
    }
    const std::string& Path() const { return mPath; }

  private:
    explicit TempFolder(std::string path) : mPath(std::move(path)) {}
    std::string mPath;
};

}  // namespace

std::optional<std::string> WhyCannotCount(const std::string& buildFlags) {
    if (!CallgrindRequestsBuiltIn())
        return "this binary was built without <valgrind/callgrind.h>: install valgrind (tools/setup.sh) "
               "and rebuild with the exact preset";
    if (buildFlags.find("-march=native") != std::string::npos)
        return "this binary was built with -march=native, which valgrind cannot run (no AVX-512): build with the "
               "exact preset (cmake --preset exact && cmake --build --preset exact) and run build/exact/cloudbench";
    if (buildFlags.find("-fsanitize=address") != std::string::npos)
        return "this binary was built with AddressSanitizer, which cannot run under valgrind: build with the exact "
               "preset";
    if (FindOnPath("valgrind").empty())
        return "valgrind is not on PATH: install the valgrind package (tools/setup.sh)";
    return std::nullopt;
}

std::vector<std::string> CallgrindOptions(const std::string& outFile, const std::string& logFile) {
    return {"--tool=callgrind",
            "--instr-atstart=no",
            "--callgrind-out-file=" + outFile,
            "--combine-dumps=yes",
            "--dump-line=no",
            "--dump-instr=no",
            "--compress-strings=no",
            "--compress-pos=no",
            "--log-file=" + logFile};
}

Result<std::string> SelfExecutable() {
    std::error_code error;
    const fs::path self = fs::read_symlink("/proc/self/exe", error);
    if (error) return MakeError("/proc/self/exe: cannot read: " + error.message());
    return self.string();
}

Result<CountRun> CountUnderCallgrind(const std::string& self, const CountRequest& request) {
    const std::string valgrind = FindOnPath("valgrind");
    if (valgrind.empty()) return MakeError("valgrind is not on PATH: install the valgrind package");
    auto folder = TempFolder::Create();
    if (!folder) return std::unexpected(folder.error());
    const std::string dir = folder->Path();
    const std::string dumpFile = dir + "/callgrind.out", logFile = dir + "/valgrind.log",
                      childFile = dir + "/child.json";

    std::vector<std::string> args = {valgrind};
    for (std::string& option : CallgrindOptions(dumpFile, logFile)) args.push_back(std::move(option));
    for (const std::string& arg : {self, std::string("count"), request.scenePath, std::string("--backend"),
                                   request.backend, std::string("--threads"), std::string("1"),
                                   std::string("--quiet"), std::string("--out"), childFile})
        args.push_back(arg);
    for (const SceneOverride& o : request.overrides) {
        args.push_back("--set");
        args.push_back(o.path + "=" + o.value);
    }
    args.insert(args.end(), request.extraArgs.begin(), request.extraArgs.end());
    std::vector<char*> argv;
    for (std::string& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);

    const auto start = std::chrono::steady_clock::now();
    pid_t pid = 0;
    if (int rc = posix_spawn(&pid, valgrind.c_str(), nullptr, nullptr, argv.data(), environ); rc != 0)
        return MakeError(valgrind + ": cannot start: " + std::strerror(rc));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return MakeError("waiting for valgrind: " + std::string(std::strerror(errno)));
    CountRun run;
    run.wallSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    const std::string log = ReadFile(logFile);
    if (const size_t at = log.find("Using Valgrind-"); at != std::string::npos) {
        const size_t from = at + std::string_view("Using ").size();
        run.valgrindVersion = log.substr(from, log.find_first_of(" \n", from) - from);
        for (char& c : run.valgrindVersion) c = char(std::tolower(static_cast<unsigned char>(c)));
    }
    const bool sigill = (WIFSIGNALED(status) && WTERMSIG(status) == SIGILL) ||
                        log.find("signal 4 (SIGILL)") != std::string::npos;
    if (sigill)
        return MakeError("the program died of SIGILL under valgrind (an instruction valgrind cannot run, such as "
                         "AVX-512): build with the exact preset (cmake --preset exact && cmake --build --preset "
                         "exact)\n" + Tail(log, 12));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        const std::string how = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                                                  : "was killed by signal " + std::to_string(WTERMSIG(status));
        return MakeError("the counting run under valgrind " + how + "; valgrind's log ends:\n" + Tail(log, 12));
    }
    const nlohmann::json child = nlohmann::json::parse(ReadFile(childFile), nullptr, /*allow_exceptions=*/false);
    if (!child.is_object() || !child.contains("device"))
        return MakeError(childFile + ": the counting run wrote no record of its backend");
    run.device = child["device"].get<std::string>();
    auto parts = ParseCallgrindDump(ReadFile(dumpFile));
    if (!parts) return MakeError(dumpFile + ": " + parts.error().message);
    auto counts = CountStageCalls(*parts);
    if (!counts) return MakeError(dumpFile + ": " + counts.error().message);
    run.counts = std::move(*counts);
    return run;
}

}  // namespace cb
