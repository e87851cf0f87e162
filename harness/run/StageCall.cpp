#include "harness/run/StageCall.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <string>
#include <vector>

#include "core/plan/StageGraph.h"
#include "harness/platform/Isolation.h"

namespace cb {
namespace {

// The test-only slowdown switch, CLOUDBENCH_TEST_SLOWDOWN=<stage>:<factor>
// (docs/cli.md): the named stage's time becomes `factor` times its own, by
// keeping the backend busy for (factor - 1) times the call's time right after
// it, inside the timed record (Backend::BusyFor: on the CPU, every thread of
// its arena, as a stage doing more work would). A spin on the calling thread
// alone let the CPU backend's workers fall asleep, and waking them slowed the
// next stage; a spin in TBB's default arena moved them out of the backend's.
// It exists so that the performance gate's tests can plant a known
// regression; nothing else reads it.
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

}  // namespace

Status CallStage(Stage stage, Backend& backend, const Scene& scene, const StageHostInputs& host,
                 const StageBuffers& buffers, StageCallRecord& record) {
    // Where a crash happens, for the parent of an isolated backend (harness/platform/Isolation.h).
    MarkPhase(StageName(stage), host.step);
    InjectTestFault(backend.Name(), StageName(stage));
    const double before = record.ms;
    Status status = AdapterOf(stage)(backend, scene, host, buffers, record);
    if (const auto& slowdown = TestSlowdown(); slowdown && slowdown->stage == StageName(stage)) {
        const auto start = std::chrono::steady_clock::now();
        backend.BusyFor((slowdown->factor - 1) * (record.ms - before));
        record.ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    if (!status && !Describe(stage).renderer)
        return MakeError(std::string(StageName(stage)) + ": " + status.error().message);
    return status;
}

}  // namespace cb
