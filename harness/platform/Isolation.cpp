#include "harness/platform/Isolation.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <thread>
#include <variant>
#include <vector>

#include "core/base/ShownText.h"
#include "core/scene/Stage.h"
#include "harness/platform/PosixIo.h"

namespace cb {
namespace {

// Where the process is, in a page the parent shares with its child (MAP_SHARED,
// created before fork). The parent reads it only after the child is dead, so
// no write can be torn; the name is still kept terminated.
struct PhaseBoard {
    char phase[64];
    uint32_t step;
    uint32_t hasStep;
};

PhaseBoard gLocalBoard{};                   // without isolation, and in a process that runs no child
PhaseBoard* gBoard = &gLocalBoard;          // the board MarkPhase writes
void* volatile gFaultAllocation = nullptr;  // the test-only "oom" fault's allocation, never reached

std::string Seconds(double s) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", s);
    return text;
}

std::string SignalName(int sig) {
    switch (sig) {
        case SIGSEGV:
            return "SIGSEGV";
        case SIGABRT:
            return "SIGABRT";
        case SIGBUS:
            return "SIGBUS";
        case SIGFPE:
            return "SIGFPE";
        case SIGILL:
            return "SIGILL";
        case SIGKILL:
            return "SIGKILL";
        case SIGTERM:
            return "SIGTERM";
        case SIGINT:
            return "SIGINT";
        case SIGPIPE:
            return "SIGPIPE";
        case SIGTRAP:
            return "SIGTRAP";
        case SIGSYS:
            return "SIGSYS";
        default:
            return "signal " + std::to_string(sig);
    }
}

void ReadBoard(const PhaseBoard& board, ChildFailure& failure) {
    char phase[sizeof board.phase + 1] = {};
    std::memcpy(phase, board.phase, sizeof board.phase);
    failure.stage = phase;
    if (board.hasStep) failure.step = board.step;
}

ChildFailure FailureHere(std::string status, std::string message) {
    ChildFailure f;
    f.status = std::move(status);
    f.message = std::move(message);
    ReadBoard(*gBoard, f);
    return f;
}

// Runs `work`, turning an exception into a failure record.
std::variant<nlohmann::json, ChildFailure> RunCaught(const IsolatedWork& work, const SendMessage& send) {
    try {
        return work(send);
    } catch (const std::bad_alloc& e) {
        return FailureHere("out of memory", e.what());
    } catch (const std::exception& e) {
        return FailureHere("failed", std::string("uncaught exception: ") + e.what());
    }
}

// The child: runs the work and sends every message and the result as lines
// of JSON ({"message": ...}, then {"result": ...} or {"failure": ...}).
[[noreturn]] void RunChild(int fd, pid_t parent, const IsolatedWork& work) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(127);  // the parent died before prctl took effect
    auto send = [&](const nlohmann::json& message) {
        if (!WriteAll(fd, nlohmann::json{{"message", message}}.dump() + "\n")) _exit(126);
    };
    auto outcome = RunCaught(work, send);
    nlohmann::json last;
    if (auto* result = std::get_if<nlohmann::json>(&outcome))
        last = {{"result", std::move(*result)}};
    else
        last = {{"failure", std::get<ChildFailure>(outcome).Json()}};
    MarkPhase("sending results");
    const bool sent = WriteAll(fd, last.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(sent ? 0 : 126);  // no atexit handlers or static destructors: they belong to the parent
}

std::optional<ChildFailure> ParseFailure(const nlohmann::json& j) {
    if (!j.is_object()) return std::nullopt;
    ChildFailure f;
    f.status = j.value("status", "failed");
    f.signal = j.value("signal", "");
    f.stage = j.value("stage", "");
    if (j.contains("step") && j["step"].is_number_unsigned()) f.step = j["step"].get<uint32_t>();
    f.message = j.value("message", "");
    return f;
}

}  // namespace

std::string ChildFailure::Describe() const {
    std::string text = status;
    if (!signal.empty()) text += " (" + signal + ")";
    if (!stage.empty()) text += (ParseStage(stage) ? " in stage " : " while ") + stage;
    if (step) text += " at step " + std::to_string(*step);
    if (!message.empty()) text += ": " + message;
    return text;
}

nlohmann::json ChildFailure::Json() const {
    nlohmann::json j = {{"status", status}};
    if (!signal.empty()) j["signal"] = signal;
    if (!stage.empty()) j["stage"] = stage;
    if (step) j["step"] = *step;
    if (!message.empty()) j["message"] = message;
    return j;
}

IsolationSettings IsolationFrom(const CommonOptions& options) { return {!options.noIsolation, options.backendTimeout}; }

void MarkPhase(std::string_view phase, std::optional<uint32_t> step) {
    PhaseBoard& b = *gBoard;
    const size_t n = std::min(phase.size(), sizeof b.phase - 1);
    std::memcpy(b.phase, phase.data(), n);
    b.phase[n] = '\0';
    b.step = step.value_or(0);
    b.hasStep = step.has_value();
}

std::string CurrentPhase() {
    ChildFailure here;
    ReadBoard(*gBoard, here);
    if (here.stage.empty()) return "";
    return here.stage + (here.step ? " at step " + std::to_string(*here.step) : "");
}

void InjectTestFault(std::string_view backend, std::string_view stage) {
    // Parsed once: "<backend>:<stage>:<kind>[:<step>]"; with a step, it fires at that step only.
    struct Fault {
        std::string backend, stage, kind;
        std::optional<uint32_t> step;
    };
    static const std::optional<Fault> fault = []() -> std::optional<Fault> {
        const char* value = std::getenv("CLOUDBENCH_TEST_FAULT");
        if (!value || !*value) return std::nullopt;
        std::vector<std::string> parts(1);
        for (const char* c = value; *c; ++c)
            if (*c == ':')
                parts.emplace_back();
            else
                parts.back().push_back(*c);
        Fault f;
        if (parts.size() == 3 || parts.size() == 4) {
            f = {parts[0], parts[1], parts[2], std::nullopt};
            if (parts.size() == 4) {
                char* end = nullptr;
                const unsigned long step = std::strtoul(parts[3].c_str(), &end, 10);
                if (parts[3].empty() || *end != '\0') parts.clear();
                f.step = uint32_t(step);
            }
        }
        if (parts.size() != 3 && parts.size() != 4) {
            std::fprintf(stderr, "CLOUDBENCH_TEST_FAULT: ignored, expected <backend>:<stage>:<kind>[:<step>]\n");
            return std::nullopt;
        }
        return f;
    }();
    if (!fault || fault->backend != backend || fault->stage != stage) return;
    if (fault->step && !(gBoard->hasStep && gBoard->step == *fault->step)) return;
    const std::string& kind = fault->kind;
    std::fprintf(stderr, "CLOUDBENCH_TEST_FAULT: %s in %.*s stage %.*s\n", kind.c_str(), int(backend.size()),
                 backend.data(), int(stage.size()), stage.data());
    std::fflush(stderr);
    if (kind == "abort") std::abort();
    if (kind == "segv") raise(SIGSEGV);
    if (kind == "hang")
        for (;;) pause();
    if (kind == "exit") _exit(3);
    if (kind == "oom") {
        // A real allocation failure: more than any address space holds
        // (stored in a global, so that the compiler cannot elide the call).
        volatile size_t bytes = size_t(1) << 62;
        gFaultAllocation = ::operator new(bytes);
    }
    std::fprintf(stderr, "CLOUDBENCH_TEST_FAULT: unknown kind '%s' (abort, segv, hang, oom, exit)\n", kind.c_str());
}

IsolatedOutcome RunIsolated(std::string_view label, const IsolationSettings& settings, const IsolatedWork& work) {
    IsolatedOutcome out;
    if (!settings.enabled) {
        MarkPhase("");
        auto outcome = RunCaught(work, [&](const nlohmann::json& m) { out.messages.push_back(m); });
        if (auto* result = std::get_if<nlohmann::json>(&outcome))
            out.result = std::move(*result);
        else
            out.failure = std::get<ChildFailure>(outcome);
        return out;
    }
    auto fail = [&](std::string status, std::string message) {
        out.failure = ChildFailure{std::move(status), "", "", std::nullopt, std::move(message)};
        return out;
    };
    void* page = mmap(nullptr, sizeof(PhaseBoard), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (page == MAP_FAILED) return fail("failed", "cannot map the stage page: " + std::string(std::strerror(errno)));
    auto* board = new (page) PhaseBoard{};
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) {
        munmap(page, sizeof(PhaseBoard));
        return fail("failed", "cannot create a pipe: " + std::string(std::strerror(errno)));
    }
    std::fflush(stdout);  // or the child would print the parent's buffered output again
    std::fflush(stderr);
    const pid_t parent = getpid();
    const pid_t child = fork();
    if (child < 0) {
        close(fds[0]);
        close(fds[1]);
        munmap(page, sizeof(PhaseBoard));
        return fail("failed", "cannot fork: " + std::string(std::strerror(errno)));
    }
    if (child == 0) {
        close(fds[0]);
        gBoard = board;
        MarkPhase("starting");
        RunChild(fds[1], parent, work);
    }
    close(fds[1]);

    // Reads the child's lines until it closes the pipe, or until the timeout.
    using Clock = std::chrono::steady_clock;
    const bool hasTimeout = settings.timeoutSeconds > 0;
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                             std::chrono::duration<double>(hasTimeout ? settings.timeoutSeconds : 0));
    auto remainingMs = [&]() -> int {
        if (!hasTimeout) return -1;
        const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
        return int(std::clamp<long long>(left, 0, 1000));  // wake at least every second
    };
    std::string buffer;
    bool timedOut = false;
    std::optional<nlohmann::json> last;
    auto takeLines = [&] {
        for (size_t end; (end = buffer.find('\n')) != std::string::npos; buffer.erase(0, end + 1)) {
            auto line = nlohmann::json::parse(buffer.begin(), buffer.begin() + ptrdiff_t(end), nullptr, false);
            if (line.is_object() && line.contains("message"))
                out.messages.push_back(std::move(line["message"]));
            else if (line.is_object())
                last = std::move(line);
        }
    };
    for (;;) {
        if (hasTimeout && Clock::now() >= deadline) {
            timedOut = true;
            break;
        }
        pollfd p{fds[0], POLLIN, 0};
        const int ready = poll(&p, 1, remainingMs());
        if (ready < 0 && errno == EINTR) continue;
        if (ready == 0) continue;
        char chunk[65536];
        const ssize_t n = read(fds[0], chunk, sizeof chunk);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;  // the child closed the pipe: it exited
        buffer.append(chunk, size_t(n));
        takeLines();
    }
    // The pipe is closed only when the child exits; wait for it, within the timeout.
    int status = 0;
    if (timedOut) kill(child, SIGKILL);
    for (;;) {
        const pid_t done = waitpid(child, &status, WNOHANG);
        if (done == child) break;
        if (done < 0 && errno != EINTR) break;
        if (!timedOut && hasTimeout && Clock::now() >= deadline) {
            timedOut = true;
            kill(child, SIGKILL);  // then reaped by the next waitpid
        }
        if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    close(fds[0]);
    ChildFailure failure;
    ReadBoard(*board, failure);
    munmap(page, sizeof(PhaseBoard));

    if (timedOut) {
        failure.status = "timed out";
        failure.message =
            std::string(label) + " ran past " + Seconds(settings.timeoutSeconds) + " s (--backend-timeout)";
        out.failure = failure;
        return out;
    }
    if (WIFSIGNALED(status)) {
        const int sig = WTERMSIG(status);
        failure.status = "crashed";
        failure.signal = SignalName(sig);
        if (sig == SIGKILL) failure.message = "killed, possibly by the kernel's out-of-memory killer";
        out.failure = failure;
        return out;
    }
    if (last && last->contains("result") && WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        out.result = std::move((*last)["result"]);
        return out;
    }
    if (last && last->contains("failure")) {
        if (auto f = ParseFailure((*last)["failure"])) {
            out.failure = *f;
            return out;
        }
    }
    failure.status = "failed";
    failure.message = WIFEXITED(status)
                          ? "exited with status " + std::to_string(WEXITSTATUS(status)) + " without a result"
                          : "ended without a result";
    out.failure = failure;
    return out;
}

std::vector<OptionSpec> IsolationOptions() {
    return {
        {"--backend-timeout", "", true,
         [](CommonOptions& o, const char* v) -> std::optional<std::string> {
             char* end = nullptr;
             const double seconds = v ? std::strtod(v, &end) : -1;
             const std::string needs = "--backend-timeout: needs seconds in [0, 10000000] (0 = no timeout)";
             if (!v) return needs;
             if (!*v || *end || !(seconds >= 0) || seconds > 1e7) return needs + ", got '" + ShownArgument(v) + "'";
             o.backendTimeout = seconds;
             return std::nullopt;
         }},
        FlagOption("--no-isolation", &CommonOptions::noIsolation),
    };
}

std::vector<OptionSpec> WithIsolationOptions(std::vector<OptionSpec> options) {
    for (OptionSpec& option : IsolationOptions()) options.push_back(std::move(option));
    return options;
}

std::string IsolationOptionsHelp() {
    return "  --backend-timeout S  kill a backend's process after S seconds (default 3600; 0 = none)\n"
           "  --no-isolation     run every backend in this process (for a debugger); a crash\n"
           "                     then ends the command\n";
}

}  // namespace cb
