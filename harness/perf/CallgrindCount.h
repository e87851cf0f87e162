// Exact mode (docs/performance.md): counts the instructions of each stage call
// by running this binary again under callgrind, in a child process that steps
// the scene on one backend at one thread (`cloudbench count` in its child
// role), and reading the dumps that the stage brackets of harness/run/StageCall.cpp
// write. `cloudbench count` is its command line; `perf record` may call it too.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/scene/Scene.h"
#include "harness/perf/CallgrindDump.h"

namespace cb {

// Why this binary cannot count instructions, or nullopt when it can:
// it lacks the client requests, its flags (`buildFlags`, the provenance's
// build.flags) hold -march=native (valgrind stops at the first AVX-512
// instruction), or valgrind is not on PATH.
std::optional<std::string> WhyCannotCount(const std::string& buildFlags);

// valgrind's options: callgrind counting Ir only, uninstrumented until the
// first stage call (core/base/CallgrindRequests.h), all dumps in one file,
// no per-line or per-instruction detail (the counts are per part).
std::vector<std::string> CallgrindOptions(const std::string& outFile, const std::string& logFile);

struct CountRequest {
    std::string scenePath;
    std::vector<SceneOverride> overrides;  // --set and --steps, as given
    std::string backend = "cpu";
    // The child's own arguments besides the scene, backend, threads and overrides
    // (e.g. --gl-context), passed on as they are.
    std::vector<std::string> extraArgs;
};

struct CountRun {
    StageCounts counts;
    double wallSeconds = 0;      // the whole valgrind run, start-up included
    std::string valgrindVersion;  // "valgrind-3.19.0", from its log; "" when not found
    std::string device;           // the backend's Device() in the child
};

// Runs `self` (the path of this binary) under valgrind as
// `count SCENE --backend B --threads 1 --quiet --out CHILD.json [--set ...]`
// in a fresh temporary folder, removed afterwards. An error says why: a SIGILL
// names the exact preset; otherwise the child's exit status and the tail of
// valgrind's log.
Result<CountRun> CountUnderCallgrind(const std::string& self, const CountRequest& request);

// The path of the running binary (/proc/self/exe resolved).
Result<std::string> SelfExecutable();

}  // namespace cb
