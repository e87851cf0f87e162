// Accuracy of the shafts of light (SPEC 18; docs/accuracy.md, "Shafts of light"): the light the shells add to a
// frame against the exact single-scattering haze reference (reference/HazeReference.h), over the shell counts
// kShaftsShellCounts without the falloff (the reference has none) and at the scene's own setting, on each backend,
// with the pass's time.
#pragma once

#include <nlohmann/json.hpp>
#include <span>

#include "core/base/Error.h"
#include "harness/accuracy/Evaluator.h"
#include "harness/report/Report.h"
#include "harness/run/Session.h"

namespace cb {

inline constexpr uint32_t kShaftsShellCounts[] = {4, 16, 64};

// The session's scene (shafts on) at its last step, its first camera: {"reference": {...}, "rows": [...]}
// (docs/results.md), a row per setting and backend.
Result<nlohmann::json> MeasureShafts(Evaluator& eval, std::span<const OpenedBackend> backends);

// The table of MeasureShafts's rows, and of its reference.
report::Table ShaftsRowsTable(const nlohmann::json& rows);

}  // namespace cb
