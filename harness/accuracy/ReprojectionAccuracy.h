// Temporal reprojection's error and speed-up (SPEC 19): the scene run twice in lock step on one backend, as it is and
// with every pixel traced (march.reprojection.block 1), and each step's ray-marched frames compared.
#pragma once

#include <nlohmann/json.hpp>

#include "core/base/Error.h"
#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "harness/report/ReportModel.h"

namespace cb {

// Per camera: every compared frame (a step's last; every frame with render.frames_per_step 1) with its PSNR against
// the full frame (ImageErrors' peak and MSE; null where equal) and both runs' render_march time, then the median and
// worst PSNR and the median times. Reprojecting scenes only (march.reprojection.block > 1).
Result<nlohmann::json> MeasureReprojection(Backend& backend, const std::string& backendName, const Scene& scene);

// The table of MeasureReprojection's summaries, one row per backend and camera (or a row {backend, error} saying why
// a backend was not measured).
report::Table ReprojectionTable(const nlohmann::json& rows);

}  // namespace cb
