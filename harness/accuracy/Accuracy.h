// Accuracy of the fast lighting stages against the exact reference (SPEC 11):
// the inputs they read, the reference for them, one stage measured on one
// backend (time and error), and the bound on the jump of T where the principal
// axis switches. The commands built on it (accuracy, sweep, dump --reference)
// are in AccuracyCommands.cpp; docs/accuracy.md describes the method.
#pragma once

#include <chrono>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/scene/Scene.h"
#include "harness/report/Report.h"
#include "reference/Reference.h"

namespace cb {

// |approx - reference| over a set of elements: max, mean, and the 99th
// percentile as the nearest-rank order statistic (the ceil(0.99 n)-th smallest).
struct ErrorStats {
    uint64_t count = 0;
    double max = 0, mean = 0, p99 = 0;
    uint64_t worst = 0;  // index of the largest error
};
// `mask` empty: every element; otherwise the elements with mask[v] != 0.
ErrorStats AbsoluteErrors(std::span<const float> approx, std::span<const float> reference,
                          std::span<const uint8_t> mask = {});

// q and D at a scene's last step (steps - 1), computed by the CPU backend with
// the scene's simulation stages only (region, ca, smooth or noise, density).
struct LightingInputs {
    Extent3 grid;
    uint32_t step = 0;
    std::vector<float> q;  // canonical, grid.Count()
    std::vector<float> D;  // nx * ny; empty when the scene has no density stage
};
Result<LightingInputs> SimulateLightingInputs(const Scene& scene, int threads);

// The reference for one q, sun, sigma and h, with the masks the error
// statistics use besides "all": voxels with q > 0 (in cloud) and ground cells
// with G_ref < 1 (under cloud).
struct ReferenceResult {
    std::vector<float> T, G;
    std::vector<uint8_t> cloud, shadowed;
    ref::TraceStats tStats, gStats;
    double buildSeconds = 0;
    size_t primitives = 0;
};
ref::ReferenceParams MakeReferenceParams(const Scene& scene, ref::RayStart start);
Result<ReferenceResult> ComputeReference(const Scene& scene, const LightingInputs& inputs, ref::RayStart start,
                                         int threads);

// Runs `call` once to warm up and `repeats` more times, timed.
template <typename Fn>
Result<Summary> TimeRepeated(int repeats, Fn&& call) {
    CB_TRY(call());
    std::vector<double> ms;
    for (int n = 0; n < repeats; ++n) {
        const auto start = std::chrono::steady_clock::now();
        CB_TRY(call());
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    return Summarize(ms);
}

// One lighting stage on one backend: time over `repeats` calls after one
// warm-up call (transfers excluded) and the error of its output.
struct StageAccuracy {
    std::string status = "ok";  // ok, unsupported, failed
    std::string detail;
    Summary timeMs;
    ErrorStats all, subset;        // subset: voxels in cloud (shade), cells under cloud (shadow)
    std::vector<float> output;     // the stage's output, kept when asked
    std::optional<double> psnrDb;  // renderers only (harness/accuracy/ImageAccuracy.h); none when infinite
};
// A row that was not measured: its status (unsupported, unavailable, failed, crashed, ...) and why.
inline StageAccuracy NotMeasured(std::string status, std::string detail) {
    StageAccuracy a;
    a.status = std::move(status);
    a.detail = std::move(detail);
    return a;
}
StageAccuracy MeasureShade(Backend& backend, const Scene& scene, const LightingInputs& inputs,
                           const ReferenceResult& reference, int repeats, bool keepOutput = false);
StageAccuracy MeasureShadow(Backend& backend, const Scene& scene, const LightingInputs& inputs,
                            const ReferenceResult& reference, int repeats);

// An a-priori bound on max |T(s_side) - T(s_tie)| for the shear-warp with
// principal axis `axis` fixed, where s_tie is the direction on the switch
// (docs/accuracy.md derives it): over the M = n_w - 1 slices after the first,
// each slice adds at most delta (1 + L_q q_max) + L_c q_max |dc| plus its
// rounding, where delta = |du - du*| + |dv - dv*| is how far the bilinear taps
// move, c = sigma h_slice / |s_w| the optical depth per unit q, and L_q, L_c
// the attenuation's slopes in q and c. Infinite for the nearest filter, whose
// taps jump.
double SwitchSideBound(const ShadeParams& params, const Extent3& grid, const Vec3& side, const Vec3& tie, int axis,
                       float qMax);

}  // namespace cb
