// Valgrind client requests that bracket each backend stage call
// (harness/run/StageCall.cpp), so that `cloudbench count` (docs/performance.md,
// "Exact mode") reads each call's instruction count from its own callgrind
// dump. Outside valgrind a request is a few register rotations and the label
// is never formatted; without <valgrind/callgrind.h> at build time they
// compile to nothing and CallgrindRequestsBuiltIn() is false.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define CLOUDBENCH_HAS_CALLGRIND_REQUESTS 1
#else
#define CLOUDBENCH_HAS_CALLGRIND_REQUESTS 0
#endif

namespace cb {

// Whether this binary was built with the client requests.
constexpr bool CallgrindRequestsBuiltIn() { return CLOUDBENCH_HAS_CALLGRIND_REQUESTS != 0; }

// Whether the process runs under valgrind (any tool).
inline bool RunningOnValgrind() {
#if CLOUDBENCH_HAS_CALLGRIND_REQUESTS
    return RUNNING_ON_VALGRIND != 0;
#else
    return false;
#endif
}

// What one dump is named: "stage=<stage> backend=<backend> step=<step>", with
// " camera=<camera>" (the rest of the name) for a renderer's per-camera call.
// ParseStageCountLabel (harness/perf/CallgrindDump.h) reads it back.
struct StageCountLabel {
    std::string_view stage;
    std::string_view backend;
    uint32_t step = 0;
    std::string_view camera;  // "" = not per camera
};

inline std::string FormatStageCountLabel(const StageCountLabel& label) {
    std::string name = "stage=" + std::string(label.stage) + " backend=" + std::string(label.backend) +
                       " step=" + std::to_string(label.step);
    if (!label.camera.empty()) name += " camera=" + std::string(label.camera);
    return name;
}

// Counts the instructions between Begin() and End() as one callgrind dump
// named by the label: Begin() zeroes the counters, End() dumps them. Nothing
// else may run between the two but the call being counted. Begin() also
// starts callgrind's instrumentation when it is off (`count` runs valgrind
// with --instr-atstart=no, so the start-up before the first stage call runs
// uninstrumented; once on, a start request does nothing).
class CallgrindStageBracket {
  public:
    explicit CallgrindStageBracket(const StageCountLabel& label) : mActive(RunningOnValgrind()) {
        if (mActive) mName = FormatStageCountLabel(label);  // formatted before Begin(): not counted
    }
    void Begin() const {
#if CLOUDBENCH_HAS_CALLGRIND_REQUESTS
        if (mActive) {
            CALLGRIND_START_INSTRUMENTATION;
            CALLGRIND_ZERO_STATS;
        }
#endif
    }
    void End() const {
#if CLOUDBENCH_HAS_CALLGRIND_REQUESTS
        if (mActive) CALLGRIND_DUMP_STATS_AT(mName.c_str());
#endif
    }

  private:
    bool mActive;
    std::string mName;
};

}  // namespace cb
