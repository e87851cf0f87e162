#include "harness/accuracy/ReprojectionAccuracy.h"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "core/stages/render_march/RenderMarch.h"
#include "harness/accuracy/ImageAccuracy.h"
#include "harness/run/Simulation.h"

namespace cb {
using nlohmann::json;

namespace {

double Median(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// The render_march time of camera `camera` in a step's record (its last frame's).
double MarchFrameMs(const StepRecord& record, const std::string& camera) {
    double ms = 0;
    for (const FrameRecord& f : record.frames)
        if (f.renderer == Stage::RenderMarch && f.camera == camera) ms = f.ms;
    return ms;
}

}  // namespace

Result<json> MeasureReprojection(Backend& backend, const std::string& backendName, const Scene& scene) {
    Scene full = scene;
    full.march.reprojectionBlock = 1;
    auto reprojected = Simulation::Create(scene, backend, /*everyStepOutputs=*/true);
    if (!reprojected) return std::unexpected(reprojected.error());
    auto traced = Simulation::Create(full, backend, /*everyStepOutputs=*/true);
    if (!traced) return std::unexpected(traced.error());
    const size_t cameras = scene.render.cameras.size();
    std::vector<json> frames(cameras, json::array());
    std::vector<std::vector<double>> psnr(cameras), ms(cameras), msFull(cameras);
    std::vector<double> worst(cameras, std::numeric_limits<double>::infinity());
    std::vector<int64_t> worstFrame(cameras, -1);
    for (uint32_t t = 0; t < scene.steps; ++t) {
        // Interleaved frame by frame, so that a loaded machine weighs on both alike.
        StepRecord a, b;
        CB_TRY((*reprojected)->Step(a));
        CB_TRY((*traced)->Step(b));
        if (a.framesRendered == 0) continue;
        const uint32_t sequence = (*reprojected)->FramesDrawn() - 1;
        for (size_t n = 0; n < cameras; ++n) {
            auto got = Download<float>(backend, *(*reprojected)->Get(Resource::MarchImage, n));
            if (!got) return std::unexpected(got.error());
            auto want = Download<float>(backend, *(*traced)->Get(Resource::MarchImage, n));
            if (!want) return std::unexpected(want.error());
            const ImageErrorStats e = ImageErrors(*got, *want);
            const std::string& name = scene.render.cameras[n].name;
            const double frameMs = MarchFrameMs(a, name), frameMsFull = MarchFrameMs(b, name);
            ms[n].push_back(frameMs);
            msFull[n].push_back(frameMsFull);
            const double value = e.psnr.value_or(std::numeric_limits<double>::infinity());
            psnr[n].push_back(value);
            if (value < worst[n]) worst[n] = value, worstFrame[n] = sequence;
            frames[n].push_back({{"frame", sequence},
                                 {"psnr_db", e.psnr ? json(*e.psnr) : json(nullptr)},
                                 {"max_error", e.pixel.max},
                                 {"ms", frameMs},
                                 {"ms_full", frameMsFull}});
        }
    }
    json rows = json::array();
    for (size_t n = 0; n < cameras; ++n) {
        const double median = Median(ms[n]), medianFull = Median(msFull[n]);
        auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
        rows.push_back({{"backend", backendName},
                        {"camera", scene.render.cameras[n].name},
                        {"block", scene.march.reprojectionBlock},
                        {"frames", frames[n]},
                        {"median_psnr_db", finite(Median(psnr[n]))},
                        {"worst_psnr_db", finite(worst[n])},
                        {"worst_frame", worstFrame[n]},
                        {"median_ms", median},
                        {"median_ms_full", medianFull},
                        {"speedup", median > 0 ? json(medianFull / median) : json(nullptr)}});
    }
    return rows;
}

report::Table ReprojectionTable(const json& rows) {
    report::Table table({report::Column("backend"), report::Column("camera"), report::Column("k").Integer(),
                         report::Column("frames").Integer(), report::Column("median PSNR").Real("%.1f").Unit("dB"),
                         report::Column("worst PSNR").Real("%.1f").Unit("dB"), report::Column("worst frame").Integer(),
                         report::Column("march").Real("%.2f").Unit("ms"),
                         report::Column("full").Real("%.2f").Unit("ms"), report::Column("speed-up").Real("%.2f")});
    auto real = [](const json& v) { return v.is_number() ? report::Cell(v.get<double>()) : report::Cell("inf"); };
    for (const json& r : rows) {
        if (r.contains("error")) {
            table.rows.push_back({r["backend"].get<std::string>(), "not measured: " + r["error"].get<std::string>()});
            table.rows.back().resize(table.columns.size());
            continue;
        }
        table.rows.push_back({r["backend"].get<std::string>(), r["camera"].get<std::string>(),
                              r["block"].get<int64_t>(), int64_t(r["frames"].size()), real(r["median_psnr_db"]),
                              real(r["worst_psnr_db"]), r["worst_frame"].get<int64_t>(), real(r["median_ms"]),
                              real(r["median_ms_full"]), real(r["speedup"])});
    }
    return table;
}

}  // namespace cb
