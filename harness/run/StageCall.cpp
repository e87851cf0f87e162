#include "harness/run/StageCall.h"

#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/plan/StageGraph.h"
#include "harness/platform/Isolation.h"

namespace cb {
namespace {

// The test-only slowdown switch, CLOUDBENCH_TEST_SLOWDOWN=<stage>:<factor>
// (docs/cli.md): the named stage does `factor` times its own work. Right
// before each call, inside its timed record, the backend spins for (factor -
// 1) times the wall and CPU time the stage's previous call took
// (Backend::BusyFor; the first call is not slowed, and is a warm-up step).
// Before, not after: the threads a stage leaves idle spin on into the next
// stage, and work added after the call would change what the next stage's
// CPU time holds. A spin on the calling thread alone let the CPU backend's
// workers fall asleep, and waking them slowed the stage; a spin in TBB's
// default arena moved them out of the backend's; a spin for a wall time did
// less work when other jobs took the cores.
struct Slowdown {
    std::string stage;
    double factor = 1;
};

const std::optional<Slowdown>& TestSlowdown() {
    static const std::optional<Slowdown> slowdown = []() -> std::optional<Slowdown> {
        const char* value = std::getenv("CLOUDBENCH_TEST_SLOWDOWN");
        if (!value || !*value) return std::nullopt;
        const std::string text = value;
        const size_t colon = text.find(':');
        char* end = nullptr;
        const double factor = colon == std::string::npos ? 0 : std::strtod(text.c_str() + colon + 1, &end);
        if (colon == std::string::npos || colon == 0 || end == text.c_str() + colon + 1 || *end != '\0' ||
            !(factor >= 1 && factor <= 1000)) {
            std::fprintf(stderr,
                         "CLOUDBENCH_TEST_SLOWDOWN: ignored, expected <stage>:<factor> with factor in [1, 1000]\n");
            return std::nullopt;
        }
        return Slowdown{text.substr(0, colon), factor};
    }();
    return slowdown;
}

// The slowed stage's last call on each backend, without its spin.
struct CallTimes {
    double wallMs = 0, cpuMs = 0;
};
std::mutex gCallsLock;
std::map<std::string, CallTimes> gCalls;

std::optional<CallTimes> PreviousCall(const std::string& backend) {
    std::lock_guard lock(gCallsLock);
    const auto found = gCalls.find(backend);
    return found == gCalls.end() ? std::nullopt : std::optional(found->second);
}

void RememberCall(const std::string& backend, CallTimes times) {
    std::lock_guard lock(gCallsLock);
    gCalls[backend] = times;
}

}  // namespace

Status CallStage(Stage stage, Backend& backend, const Scene& scene, const StageHostInputs& host,
                 const StageBuffers& buffers, StageCallRecord& record) {
    // Where a crash happens, for the parent of an isolated backend (harness/platform/Isolation.h).
    MarkPhase(StageName(stage), host.step);
    InjectTestFault(backend.Name(), StageName(stage));
    const auto& slowdown = TestSlowdown();
    // A factor of 1 is the control (tests/check_perf_gate.py runs BASE with <stage>:1 and HEAD with <stage>:2):
    // it calls the spin for no time, which still runs a task on every thread of the arena, as a slowed run's
    // spin does, so that the two sides differ in the spin's length alone.
    const bool slowed = slowdown && slowdown->stage == StageName(stage);
    if (slowed)
        if (const auto previous = PreviousCall(backend.Name())) {
            CallClock clock(record);
            backend.BusyFor((slowdown->factor - 1) * previous->wallMs, (slowdown->factor - 1) * previous->cpuMs);
            clock.Stop();
        }
    const double before = record.ms, cpuBefore = record.cpuMs;
    Status status = AdapterOf(stage)(backend, scene, host, buffers, record);
    if (slowed) RememberCall(backend.Name(), {record.ms - before, record.cpuMs - cpuBefore});
    if (!status && !Describe(stage).renderer)
        return MakeError(std::string(StageName(stage)) + ": " + status.error().message);
    return status;
}

}  // namespace cb
