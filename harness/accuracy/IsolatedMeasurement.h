// accuracy and sweep with crash isolation: each backend's measurements run in
// a process of its own (harness/platform/Isolation.h), which opens the backend and
// computes the CPU inputs and the Embree reference it needs (TBB may not run
// in the parent before a fork, so the reference is not shared between
// backends: its cost is paid once per backend). The parent merges the rows
// in the order one process measuring every backend would give.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "harness/accuracy/Measurement.h"
#include "harness/platform/Isolation.h"

namespace cb {

// Measures `stages` of one setting on every available backend into `rows`.
Status MeasureSetting(Evaluator& eval, const std::vector<SceneOverride>& setting, std::span<const Stage> stages,
                      std::span<const OpenedBackend> backends, std::vector<Row>& rows);

// One setting's stages, measured in plan order.
struct PlannedSetting {
    std::vector<SceneOverride> setting;
    std::vector<Stage> stages;
};

// What one backend's process returned.
struct BackendMeasurement {
    std::string name;
    bool available = false;
    std::string status, reason;          // as opened: "available", "unavailable" or "unsupported", and why
    std::vector<std::vector<Row>> rows;  // per plan item
    std::vector<ReferenceRecord> records;
    nlohmann::json extra;                 // what `more` returned
    std::optional<ChildFailure> failure;  // the process gave no result
};

// Work after the plan, in the child, on the opened backend (one slot); its
// JSON comes back as BackendMeasurement::extra.
using MoreMeasurements = std::function<Result<nlohmann::json>(Evaluator& eval, std::span<const OpenedBackend> backend)>;

// Measures `plan` on each of `names`, each in its own process, with the
// command's --repeat and --reference-step (`measurement`). An error in the
// measurement itself (not the backend's crash: the reference or the inputs)
// ends it with the error. `progress` (optional) is called after each plan item in the child.
Result<std::vector<BackendMeasurement>> MeasureEachBackend(Session& session, const MeasurementOptions& measurement,
                                                           const std::vector<std::string>& names,
                                                           const std::vector<PlannedSetting>& plan,
                                                           const MoreMeasurements& more = {},
                                                           const std::function<void(size_t)>& progress = {});

// The rows of every backend, plan item by plan item, backend by backend; a
// backend that did not open or whose process died has a row per planned
// stage with its status ("unavailable", "crashed", ...) and the reason.
// `itemOf` (optional) gets each row's plan item.
std::vector<Row> MergeRows(const Scene& scene, const std::vector<PlannedSetting>& plan,
                           const std::vector<BackendMeasurement>& parts, std::vector<size_t>* itemOf = nullptr);
// The reference records of the first backend that computed any.
std::vector<ReferenceRecord> FirstRecords(const std::vector<BackendMeasurement>& parts);

}  // namespace cb
