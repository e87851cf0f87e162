#include "harness/accuracy/ImageAccuracy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <numbers>

#include "core/scene/SceneNames.h"
#include "core/stages/shade/Shade.h"
#include "core/stages/shade_sky/ShadeSky.h"
#include "harness/platform/Isolation.h"

namespace cb {
using nlohmann::json;

ImageErrorStats ImageErrors(std::span<const float> approx, std::span<const float> reference) {
    ImageErrorStats out;
    const size_t n = std::min(approx.size(), reference.size()) / 3;
    std::vector<float> perPixel(n), zero(n, 0.0f);
    double sq = 0;
    for (size_t p = 0; p < n; ++p) {
        float e = 0;
        for (int c = 0; c < 3; ++c) {
            const double d = double(approx[3 * p + c]) - double(reference[3 * p + c]);
            e = std::max(e, float(std::fabs(d)));
            sq += d * d;
            out.peak = std::max(out.peak, double(reference[3 * p + c]));
        }
        perPixel[p] = e;
    }
    out.pixel = AbsoluteErrors(perPixel, zero);
    out.mse = n ? sq / double(3 * n) : 0.0;
    if (out.peak <= 0) out.peak = 1;  // a black reference: the display's white
    if (out.mse > 0) out.psnr = 10 * std::log10(out.peak * out.peak / out.mse);
    return out;
}

namespace {

RenderAccuracy RenderNotMeasured(std::string status, std::string detail) {
    RenderAccuracy a;
    a.status = std::move(status);
    a.detail = std::move(detail);
    return a;
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

json ImageRowJson(Stage renderer, const std::string& backend, const std::vector<SceneOverride>& setting,
                  const std::string& referencePhase, const RenderAccuracy& a) {
    json settings = json::object();
    for (const SceneOverride& o : setting) settings[o.path] = o.value;
    json j = {{"renderer", StageName(renderer)},
              {"backend", backend},
              {"settings", settings},
              {"label", SettingsLabel(setting)},
              {"reference_phase", referencePhase},
              {"status", a.status}};
    if (!a.detail.empty()) j["detail"] = a.detail;
    if (a.status == "ok") {
        j["time"] = TimeJson(a.timeMs);
        j["prep_ms"] = a.prepMs;
        j["error"] = {{"count", a.error.pixel.count},
                      {"max", a.error.pixel.max},
                      {"mean", a.error.pixel.mean},
                      {"p99", a.error.pixel.p99},
                      {"worst_index", a.error.pixel.worst},
                      {"mse", a.error.mse},
                      {"peak", a.error.peak},
                      {"psnr_db", a.error.psnr ? json(*a.error.psnr) : json(nullptr)}};
    }
    return j;
}

Status MeasureImageRows(ImageReferences& refs, const Session& session, int repeats,
                        const std::vector<SceneOverride>& setting, std::span<const OpenedBackend> backends,
                        std::span<const Stage> renderers, json& rows) {
    auto loaded = refs.Load(setting);
    if (!loaded) {
        // A setting the scene refuses (e.g. a light source that needs a stage the scene lacks).
        for (Stage r : renderers)
            for (const OpenedBackend& slot : backends)
                rows.push_back(
                    ImageRowJson(r, slot.name, setting, "", RenderNotMeasured("invalid", loaded.error().message)));
        return {};
    }
    for (Stage r : renderers)
        for (const OpenedBackend& slot : backends) {
            // A backend without the renderer has one "unsupported" row, at the scene's settings.
            if (slot.backend && !slot.backend->Supports(r) && !setting.empty()) continue;
            RenderAccuracy a = slot.backend ? MeasureRender(*slot.backend, r, loaded->scene, *loaded->in,
                                                            loaded->reference->result.image, repeats)
                                            : RenderNotMeasured("unavailable", slot.reason);
            if (a.status != "ok" && !session.Options().quiet)
                std::fprintf(stderr, "%s %s %s: %s: %s\n", slot.name.c_str(), std::string(StageName(r)).c_str(),
                             SettingsLabel(setting).c_str(), a.status.c_str(), a.detail.c_str());
            rows.push_back(ImageRowJson(r, slot.name, setting, loaded->reference->phase, a));
        }
    return {};
}

}  // namespace

RenderAccuracy MeasureRender(Backend& backend, Stage renderer, const Scene& scene, const LightingInputs& in,
                             std::span<const float> reference, int repeats) {
    const RendererDescriptor* descriptor = Describe(renderer).renderer;
    if (!descriptor || !descriptor->accuracyRender) return RenderNotMeasured("failed", "not a renderer");
    if (!backend.Supports(renderer))
        return RenderNotMeasured("unsupported",
                                 backend.Name() + " does not implement " + std::string(StageName(renderer)) + " yet");
    if (scene.render.cameras.empty()) return RenderNotMeasured("failed", "the scene has no camera");
    auto fail = [](const std::string& what, const Error& e) { return RenderNotMeasured("failed", what + e.message); };
    auto q = backend.CreateBuffer(BufferFormat::F32, in.grid);
    if (!q) return fail("", q.error());
    if (Status s = backend.Upload(**q, std::as_bytes(std::span(in.q))); !s) return fail("", s.error());
    auto image = backend.CreateBuffer(BufferFormat::F32, {3, scene.render.width, scene.render.height});
    if (!image) return fail("", image.error());
    RenderAccuracy a;
    // T from shade, T_sky from shade_sky, on this backend when the renderer reads them, untimed in the render's time.
    std::unique_ptr<Buffer> T, skyT;
    std::optional<std::string> unsupported;
    auto shadeInto = [&](Stage stage, const char* feeds, std::unique_ptr<Buffer>& out,
                         const std::function<Status(Buffer&)>& shade) -> Result<const Buffer*> {
        const std::string name(StageName(stage));
        if (!backend.Supports(stage)) {
            unsupported = backend.Name() + " does not implement " + name + ", which feeds " + feeds;
            return MakeError(*unsupported);
        }
        auto t = backend.CreateBuffer(BufferFormat::F32, in.grid);
        if (!t) return std::unexpected(t.error());
        out = std::move(*t);
        const auto start = std::chrono::steady_clock::now();
        if (Status s = shade(*out); !s) return MakeError(name + ": " + s.error().message);
        a.prepMs += MillisecondsSince(start);
        return out.get();
    };
    AccuracyRenderInputs inputs{q->get(), image->get(), &scene.render.cameras[0], in.step, nullptr, nullptr};
    inputs.shadedT = [&] {
        return shadeInto(Stage::Shade, "T", T,
                         [&](Buffer& b) { return backend.Shade(MakeShadeParams(scene), **q, b); });
    };
    inputs.shadedSkyT = [&] {
        return shadeInto(Stage::ShadeSky, "T_sky", skyT,
                         [&](Buffer& b) { return backend.ShadeSky(MakeShadeSkyParams(scene), **q, b); });
    };
    auto render = descriptor->accuracyRender(backend, scene, inputs);
    if (!render) return RenderNotMeasured(unsupported ? "unsupported" : "failed", render.error().message);
    a.prepMs += render->prepMs;
    MarkPhase(StageName(renderer), in.step);
    InjectTestFault(backend.Name(), StageName(renderer));
    const Result<Summary> time = TimeRepeated(repeats, render->call);
    if (!time) return fail(std::string(StageName(renderer)) + ": ", time.error());
    a.timeMs = *time;
    std::vector<float> out(size_t(3) * scene.render.width * scene.render.height);
    if (Status s = backend.Download(**image, std::as_writable_bytes(std::span(out))); !s) return fail("", s.error());
    // A NaN or infinity would make every statistic meaningless (and PSNR look perfect): a failed row.
    if (const size_t bad = size_t(std::ranges::count_if(out, [](float v) { return !std::isfinite(v); })))
        return RenderNotMeasured("failed", std::to_string(bad) + " of the image's " + std::to_string(out.size()) +
                                               " channel values are not finite");
    a.error = ImageErrors(out, reference);
    return a;
}

Result<StageAccuracy> MeasureImageStage(Evaluator& eval, const std::vector<SceneOverride>& setting, Stage renderer,
                                        Backend& backend) {
    auto loaded = eval.Images().Load(setting);
    if (!loaded) return std::unexpected(loaded.error());
    const RenderAccuracy a = MeasureRender(backend, renderer, loaded->scene, *loaded->in,
                                           loaded->reference->result.image, eval.Measurement().repeats);
    StageAccuracy out;
    out.status = a.status;
    out.detail = a.detail;
    out.timeMs = a.timeMs;
    out.all = a.error.pixel;
    out.psnrDb = a.error.psnr;
    return out;
}

Result<json> MeasureImages(Evaluator& eval, const Session& session, std::span<const OpenedBackend> backends) {
    const Scene& scene = session.GetScene();
    ImageReferences& refs = eval.Images();
    const int repeats = eval.Measurement().repeats;
    json rows = json::array();
    for (Stage stage : RendererStages()) {
        const RendererDescriptor* renderer = Describe(stage).renderer;
        if (!scene.stages.Has(stage)) continue;
        const Stage one[] = {stage};
        CB_TRY(MeasureImageRows(refs, session, repeats, {}, backends, one, rows));
        if (renderer->accuracyVariants)
            for (const auto& v : renderer->accuracyVariants(scene))
                CB_TRY(MeasureImageRows(refs, session, repeats, v, backends, one, rows));
    }
    return json{{"rows", rows}, {"references", refs.Records()}};
}

std::string TimeCell(const json& time) {
    return Fmt("%.3f", time["median_ms"].get<double>()) + " (" + Fmt("%.3f", time["q1_ms"].get<double>()) + "-" +
           Fmt("%.3f", time["q3_ms"].get<double>()) + ")";
}

void AppendImageErrorCells(const json& error, std::vector<report::Cell>& cells) {
    cells.push_back(error["max"].get<double>());
    cells.push_back(error["mean"].get<double>());
    cells.push_back(error["p99"].get<double>());
    if (error["psnr_db"].is_null())
        cells.push_back("inf");
    else
        cells.push_back(error["psnr_db"].get<double>());
}

report::Table ImageRowsTable(const json& rows) {
    using report::Column;
    report::Table table({Column("renderer"), Column("setting"), Column("backend"), Column("time ms (q1-q3)").Unit("ms"),
                         Column("T etc. ms").Real("%.3f").Unit("ms"), Column("max").Real("%.3g"),
                         Column("mean").Real("%.3g"), Column("p99").Real("%.3g"), Column("PSNR dB").Real("%.2f"),
                         Column("reference phase")});
    for (const json& r : rows) {
        std::vector<report::Cell> cells = {r["renderer"].get<std::string>(), r["label"].get<std::string>(),
                                           r["backend"].get<std::string>()};
        if (r["status"] != "ok") {
            cells.push_back(r["status"].get<std::string>() + ": " + r.value("detail", std::string()));
            table.rows.push_back(std::move(cells));
            continue;
        }
        cells.push_back(TimeCell(r["time"]));
        cells.push_back(r["prep_ms"].get<double>());
        AppendImageErrorCells(r["error"], cells);
        cells.push_back(r["reference_phase"].get<std::string>());
        table.rows.push_back(std::move(cells));
    }
    return table;
}

report::Table ImageReferenceTable(const json& references) {
    using report::Column;
    report::Table table({Column("reference inputs"), Column("phase"), Column("step voxel").Real("%.4g"),
                         Column("image"), Column("samples").Integer(), Column("light rays").Integer(),
                         Column("s").Real("%.3f").Unit("s"), Column("M light rays/s").Real("%.3f")});
    for (const json& r : references)
        table.rows.push_back(
            {r["inputs"].get<std::string>(), r["phase"].get<std::string>(), r["step_voxels"].get<double>(),
             std::to_string(r["width"].get<uint32_t>()) + "x" + std::to_string(r["height"].get<uint32_t>()),
             int64_t(r["samples"].get<uint64_t>()), int64_t(r["light_rays"].get<uint64_t>()),
             r["seconds"].get<double>(), r["rays_per_s"].get<double>() / 1e6});
    return table;
}

}  // namespace cb
