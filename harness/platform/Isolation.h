// Crash isolation (deqp-runner style): each backend's work runs in a child
// process of its own, so that a backend that crashes, hangs past a timeout or
// runs out of memory is reported with its signal or reason and the stage it
// was in, and every other backend's results are kept.
//
// Fork safety: the parent must not have opened any GL, Vulkan or TBB state
// before RunIsolated, so backends (and the CPU reference) are opened in the
// child, and what the parent needs comes back as JSON over a pipe.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "harness/platform/Command.h"

namespace cb {

// Why a child gave no result.
struct ChildFailure {
    std::string status;  // "crashed", "timed out", "out of memory" or "failed"
    std::string signal;  // "SIGSEGV", ...; "" when it was not killed by a signal
    std::string stage;   // the stage or phase it was in ("shade", "opening backend"); "" when unknown
    std::optional<uint32_t> step;
    std::string message;  // e.g. "exited with status 3", "std::bad_alloc"

    // "crashed (SIGSEGV) in stage shade at step 2"
    std::string Describe() const;
    // {"status", "signal", "stage", "step", "message"}; empty fields left out.
    nlohmann::json Json() const;
};

// What one isolated piece of work produced: the messages it sent as it went,
// and its result, or why there is none.
struct IsolatedOutcome {
    std::vector<nlohmann::json> messages;
    std::optional<nlohmann::json> result;
    std::optional<ChildFailure> failure;
};

struct IsolationSettings {
    bool enabled = true;           // false: run in this process (--no-isolation)
    double timeoutSeconds = 3600;  // 0 = no timeout; not applied without isolation
};
IsolationSettings IsolationFrom(const CommonOptions& options);

// Sends one message to the parent at once (a step's timing), so that it is
// kept even if the child dies later.
using SendMessage = std::function<void(const nlohmann::json&)>;
using IsolatedWork = std::function<nlohmann::json(const SendMessage&)>;

// Runs `work` in a child process (or in this one when !settings.enabled) and
// waits for it, killing it with SIGKILL past the timeout. The child dies with
// the parent (PR_SET_PDEATHSIG). A std::bad_alloc escaping `work` becomes an
// "out of memory" failure with the stage it was in; any other exception a
// "failed" one. `label` names the work in messages.
IsolatedOutcome RunIsolated(std::string_view label, const IsolationSettings& settings, const IsolatedWork& work);

// The stage or phase the current process is in, read by the parent when its
// child dies. CallStage marks each stage with its step; commands mark the
// phases between ("opening backend", "writing frames"). Cheap: a copy into a
// shared page, no locking.
void MarkPhase(std::string_view phase, std::optional<uint32_t> step = std::nullopt);

// The phase last marked in this process ("" when none), with " at step N".
std::string CurrentPhase();

// The test-only fault switch, CLOUDBENCH_TEST_FAULT=<backend>:<stage>:<kind>
// with kind abort, segv, hang, oom or exit (docs/cli.md): when `backend` and
// `stage` match, aborts, raises SIGSEGV, sleeps forever, makes an allocation
// that fails (std::bad_alloc), or exits with status 3. Does nothing otherwise.
void InjectTestFault(std::string_view backend, std::string_view stage);

// --backend-timeout SECONDS and --no-isolation, for the isolating commands.
std::vector<OptionSpec> IsolationOptions();
// `options` followed by IsolationOptions().
std::vector<OptionSpec> WithIsolationOptions(std::vector<OptionSpec> options);
// Their help lines.
std::string IsolationOptionsHelp();

}  // namespace cb
