// Which varied fields can change a stage's row in `cloudbench sweep`
// (docs/accuracy.md, "Sweeps: which rows, the Pareto front and ties"), from the
// stages' descriptors: a stage is measured once per distinct setting of the
// fields its row depends on.
#pragma once

#include <span>
#include <string_view>
#include <vector>

#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "core/scene/Stage.h"
#include "harness/run/VaryAxes.h"

namespace cb {

// Whether `path` can change a row of `stage` as sweep measures it: its output (StageOutputReads), or for a
// renderer the exact reference render it is compared with (the fields the reference renderer's output reads
// that the reference does not ignore, ReferenceRenderIgnores).
bool RowDependsOn(Stage stage, std::string_view path);

// The overrides of `setting` that a row of `stage` depends on, in their order.
std::vector<SceneOverride> SettingsRead(Stage stage, std::span<const SceneOverride> setting);

// The stages a sweep over `axes` measures: shade and shadow, and the renderers when a field of the march,
// render, lightning, phase or layers section varies (their reference render costs most), each only when a
// varied field can change its rows (RowDependsOn).
std::vector<Stage> SweepStages(const std::vector<SweepAxis>& axes);

// For each point of `points` (VaryPoints' order), the stages of `stages` measured there: each stage at the
// first point of every distinct setting of the axes its rows depend on, none at the others.
std::vector<std::vector<Stage>> DistinctMeasurements(const std::vector<std::vector<SceneOverride>>& points,
                                                     std::span<const Stage> stages);

}  // namespace cb
