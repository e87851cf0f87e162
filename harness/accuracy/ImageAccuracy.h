// Accuracy of the renderers' images against the exact reference render
// (reference/MarchReference.h; docs/accuracy.md, "Images: the reference
// render and the renderers' error"): per-pixel error = max over the three
// channels of |C - C_ref| (linear HDR), its max, mean and p99 over pixels,
// and PSNR; one renderer x backend x setting measured per call.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "harness/accuracy/Accuracy.h"
#include "harness/accuracy/Evaluator.h"
#include "harness/accuracy/Measurement.h"
#include "reference/MarchReference.h"

namespace cb {

// Errors of one finite image against the reference, 3 floats per pixel. PSNR =
// 10 log10(peak^2 / MSE), peak = the reference image's largest channel value
// (1 when the reference is black), MSE over every channel of every pixel;
// nullopt when MSE = 0 (infinite).
struct ImageErrorStats {
    ErrorStats pixel;  // per-pixel max over channels of |d|
    double mse = 0, peak = 0;
    std::optional<double> psnr;
};
ImageErrorStats ImageErrors(std::span<const float> approx, std::span<const float> reference);

// One renderer on one backend (its descriptor's accuracyRender): the render call
// alone timed over `repeats` calls after a warm-up; the inputs it reads
// (T from shade, the density stage's occupancy for the splat renderer) are
// computed first on the same backend, untimed there, and their time is
// reported as prepMs.
struct RenderAccuracy {
    std::string status = "ok";  // ok, unsupported, failed
    std::string detail;
    Summary timeMs;
    double prepMs = 0;
    ImageErrorStats error;
};
RenderAccuracy MeasureRender(Backend& backend, Stage renderer, const Scene& scene, const LightingInputs& in,
                             std::span<const float> reference, int repeats);

// Every image row of the session's scene on `backends` (one process's slot),
// as JSON: {"rows": [...], "references": [...]} (docs/results.md). Rows: each
// renderer the scene runs, in stage order, with the scene's settings and then
// each of its descriptor's accuracyVariants.
Result<nlohmann::json> MeasureImages(Evaluator& eval, const Session& session, std::span<const OpenedBackend> backends);
// One renderer of one setting on one backend as a Row's result (sweep): the
// per-pixel errors in `all`, PSNR in psnrDb; the reference is the setting's
// (Mie when it varies the phase), cached in eval.Images().
Result<StageAccuracy> MeasureImageStage(Evaluator& eval, const std::vector<SceneOverride>& setting, Stage renderer,
                                        Backend& backend);

// The Markdown/text table of image rows (as MeasureImages writes them).
report::Table ImageRowsTable(const nlohmann::json& rows);
// A row's "time" (TimeJson) as "median (q1-q3)" ms; its "error" (max, mean, p99, psnr_db) as four cells.
std::string TimeCell(const nlohmann::json& time);
void AppendImageErrorCells(const nlohmann::json& error, std::vector<report::Cell>& cells);
report::Table ImageReferenceTable(const nlohmann::json& references);

}  // namespace cb
