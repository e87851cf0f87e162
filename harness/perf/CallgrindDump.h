// Reads callgrind's output files (the "callgrind format" of the valgrind
// manual) for `cloudbench count`: each dump part's trigger and its total
// instruction count (event Ir), and the stage calls named by the client
// requests of core/base/CallgrindRequests.h.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"

namespace cb {

// One dump: "desc: Trigger: <trigger>" and the part's total of event Ir.
struct CallgrindPart {
    std::string trigger;        // e.g. "Client Request: stage=ca backend=cpu step=3", "Program termination"
    uint64_t instructions = 0;  // "totals:" (or, in older files, "summary:"), Ir column
};

// Parses one callgrind output file, with one dump or several (--combine-dumps=yes).
// Every part must declare "events:" with Ir among them and give its total.
// Errors read "line N: reason".
Result<std::vector<CallgrindPart>> ParseCallgrindDump(std::string_view text);

// A stage call's dump name, read back: "stage=S backend=B step=T[ camera=C]".
struct StageCountName {
    std::string stage;
    std::string backend;
    uint32_t step = 0;
    std::string camera;  // "" = not per camera
};
// Reads a dump name (FormatStageCountLabel); nullopt when it is not one.
std::optional<StageCountName> ParseStageCountName(std::string_view name);

// Instruction counts by backend, stage and step; a renderer's cameras are summed.
using StepCounts = std::map<uint32_t, uint64_t>;
using StageCounts = std::map<std::string, std::map<std::string, StepCounts>>;  // backend -> stage -> step

// The stage calls among `parts`: those triggered by "Client Request: <name>".
// Parts with other triggers (program termination) are not stage calls and are
// skipped; a client request whose name is not a stage call's is an error, as
// is a stage, step and camera counted twice.
Result<StageCounts> CountStageCalls(const std::vector<CallgrindPart>& parts);

}  // namespace cb
