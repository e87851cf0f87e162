// What a run reports: per-stage timing statistics, cover, results.json
// (format in docs/results.md), the frames and the top-view PNG of the density
// map. Every file is written atomically (Session::WriteAtomically).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "harness/report/ReportModel.h"
#include "harness/run/Simulation.h"

namespace cb {

// Order statistics of a sample (quantiles interpolate linearly between order
// statistics, NumPy's default "linear" method).
struct Summary {
    size_t count = 0;
    double median = 0, q1 = 0, q3 = 0, min = 0, max = 0;
};
Summary Summarize(std::vector<double> samples);

// Everything one backend produced for a run; kept even when the run stopped
// early, so that nothing already computed is lost.
struct BackendRun {
    std::string name;
    std::string device;
    std::string status = "ok";  // "ok", "unavailable" or "failed"
    std::string error;
    std::optional<uint64_t> plannedBytes;  // the scene's buffers and scratch on this backend (PlannedBytes)
    std::vector<StepRecord> steps;
    // Read-backs of outputs (frames, density map), timed apart from the stages.
    std::vector<double> downloadMs;
};

// The whole loop over the steps after warm-up (simulation, shading and every
// frame, wall time): frames drawn (each frame is one image per camera and
// renderer), steps, their wall time, and the frame rate that gives.
struct LoopFigures {
    uint64_t frames = 0;
    uint32_t steps = 0;
    uint32_t renderSteps = 0;  // steps that drew frames
    double wallMs = 0;
    std::vector<double> stepMs;   // each step's wall time
    std::vector<double> frameMs;  // each frame's wall time (StepRecord::frameMs): what the viewer waits per frame
    // The slowest frame: its step, its index in the step and what it computed ("" for renders alone).
    uint32_t slowestStep = 0, slowestFrame = 0;
    std::string slowestWork;
    std::optional<double> Fps() const {
        if (frames == 0 || !(wallMs > 0)) return std::nullopt;
        return double(frames) * 1000.0 / wallMs;
    }
};
LoopFigures MeasureLoop(const Scene& scene, const BackendRun& run);

// How often an enabled stage ran over all of a run's steps: `ran` steps, and
// the steps it skipped because none of its inputs (the sun's direction
// included) changed; the rest are steps that were not output steps.
// Renderers also count their frames (ran x render.frames_per_step).
struct StageRunCount {
    uint32_t ran = 0, skippedUnchanged = 0, notOutputStep = 0;
    uint64_t frames = 0;
};
StageRunCount CountStageRuns(const BackendRun& run, Stage stage);

nlohmann::json ResultsJson(const Scene& scene, const std::vector<BackendRun>& runs);
// One backend's "timing" object of results.json (docs/results.md): the modes
// its steps ran in, and per mode the steps after warm-up, their wall time,
// submissions, host waits and batches, each stage's wall (synchronized) or
// host recording (pipelined) time and device time, and each frame's.
nlohmann::json TimingJson(const Scene& scene, const BackendRun& run);

// One backend's section of `run`'s report: its device and steps, the
// per-stage timing table (stages in the order a step runs them, "-" for one
// with no sample after warm-up; each camera's frames) and the cover line.
report::Section TimingSection(const Scene& scene, const BackendRun& run);

// Writes a float volume (x fastest, extent `e`) as an OpenVDB file of one fog-volume grid named `name`, voxel
// (i, j, k) at world `origin` + (i + 1/2, j + 1/2, k + 1/2) `voxelSize` (images::Module::writeVdb), atomically.
Status WriteVdbVolume(const std::string& path, const std::string& name, const std::vector<float>& values,
                      const Extent3& e, const std::array<double, 3>& origin, double voxelSize);

// Writes D as a grey top view (x right, y up, white = densest column), 8-bit
// PNG through the image module. `columnSum` is canonical D, nx*ny floats.
Status WriteTopView(const std::string& path, const std::vector<float>& columnSum, uint32_t nx, uint32_t ny,
                    uint32_t nz);

// An image comparison by a CompareRule of kind Image (default: SPEC 8's, per
// channel |d| <= 2/255 on at least 99.9 % of pixels and <= 8/255 everywhere),
// with PSNR and mean absolute error, from OpenImageIO's ImageBufAlgo::compare
// (through the image module: an error only when the module cannot be loaded).
struct ImageComparison {
    CompareRule rule;
    double maxError = 0, meanError = 0, psnr = 0;
    size_t pixelsOverTolerance = 0;  // pixels with a channel off by more than rule.tolerance
    size_t pixels = 0;
    int worstX = 0, worstY = 0;
    bool Passes() const { return maxError <= rule.limit && double(pixelsOverTolerance) <= rule.share * double(pixels); }
};
Result<ImageComparison> CompareImages(const std::vector<float>& reference, const std::vector<float>& candidate,
                                      uint32_t width, uint32_t height,
                                      const CompareRule& rule = ImageRuleSpec8());
// Writes |reference - candidate| as an EXR (for a failed comparison).
Status WriteDifferenceImage(const std::string& path, const std::vector<float>& reference,
                            const std::vector<float>& candidate, uint32_t width, uint32_t height);

// The short name of a renderer stage in file names (its descriptor's fileStem).
std::string_view RendererFileName(Stage renderer);
// "frame-<renderer>-<camera>", with "-<backend>" when `backend` is not empty.
std::string FrameFileStem(Stage renderer, const std::string& camera, const std::string& backend = "");

// Writes a linear RGB float image (3 floats a pixel, row 0 at the top) as
// `stem`.exr (float, linear) and, with png = true, `stem`.png (8-bit sRGB),
// through the image module. Returns the paths written.
// The PNG of an HDR frame is tone-mapped (FrameToneMap, core/pipeline/StageDescriptor.h); the EXR stays linear.

Result<std::vector<std::string>> WriteFrame(const std::string& stem, const std::vector<float>& rgb, uint32_t width,
                                            uint32_t height, bool png = true,
                                            const std::optional<FrameToneMap>& toneMap = std::nullopt);

// The post-warm-up samples of a BackendRun that results.json (ResultsJson.cpp) and `run`'s timing
// section (TimingSection.cpp) both read.

// Which of a stage's times a sample is: its wall time (pipelined, the host's
// recording time), the process's CPU time over its calls (synchronized only),
// or its device time (where the backend measures it).
enum class StageClock { Wall, Cpu, Device };

// Post-warm-up samples of one stage on `clock`, from the steps that measured
// the stage in `mode`.
std::vector<double> StageSamples(const Scene& scene, const BackendRun& run, Stage stage,
                                 StageClock clock = StageClock::Wall, TimingMode mode = TimingMode::Synchronized);

// The share of the grid's columns that `columns` covered columns are.
double CoverFraction(const Scene& scene, uint32_t columns);

// The post-warm-up steps timed in `mode`.
std::vector<const StepRecord*> StepsIn(const Scene& scene, const BackendRun& run, TimingMode mode);

// fn(step, frame) for the post-warm-up frames of one renderer and camera, in
// order, whatever mode drew them.
template <typename Fn>
void ForEachFrame(const BackendRun& run, Stage renderer, const std::string& camera, Fn&& fn) {
    for (const StepRecord& r : run.steps)
        for (const FrameRecord& f : r.frames)
            if (f.renderer == renderer && f.camera == camera) fn(r, f);
}

}  // namespace cb
