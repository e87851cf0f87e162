#include "harness/accuracy/ShaftsAccuracy.h"

#include <algorithm>
#include <vector>

#include "core/pipeline/ShaftsPass.h"
#include "harness/accuracy/ImageAccuracy.h"
#include "harness/accuracy/Measurement.h"
#include "reference/HazeReference.h"

namespace cb {
using nlohmann::json;

namespace {

// The shells' light alone on `backend`: AddShafts into a black image, timed over `repeats` calls (the image then
// holds their sum, so the measured image is a fresh call's).
Result<std::pair<Summary, std::vector<float>>> ShellsImage(Backend& backend, const ShaftsFrame& frame,
                                                           std::span<const float> D, const Extent3& columns,
                                                           int repeats) {
    auto columnSum = backend.CreateBuffer(BufferFormat::F32, columns);
    if (!columnSum) return std::unexpected(columnSum.error());
    auto image = backend.CreateBuffer(BufferFormat::F32, {3, frame.width, frame.height});
    if (!image) return std::unexpected(image.error());
    CB_TRY(backend.Upload(**columnSum, std::as_bytes(D)));
    std::vector<float> out(size_t(3) * frame.width * frame.height, 0.0f);
    auto time = TimeRepeated(repeats, [&] { return backend.AddShafts(frame, **columnSum, **image); });
    if (!time) return std::unexpected(time.error());
    CB_TRY(backend.Upload(**image, std::as_bytes(std::span(out))));
    CB_TRY(backend.AddShafts(frame, **columnSum, **image));
    CB_TRY(backend.Download(**image, std::as_writable_bytes(std::span(out))));
    return std::pair{*time, std::move(out)};
}

}  // namespace

Result<json> MeasureShafts(Evaluator& eval, std::span<const OpenedBackend> backends) {
    const Scene& scene = eval.GetSession().GetScene();
    if (scene.render.cameras.empty()) return MakeError("the scene has no camera");
    auto inputs = eval.Inputs(scene, eval.Options().overrides);
    if (!inputs) return std::unexpected(inputs.error());
    const LightingInputs& in = **inputs;
    if (in.D.empty()) return MakeError("the scene has no density stage, so no D to light the haze through");
    const CameraFrame camera = MakeCameraFrame(scene.render.cameras[0], scene.render.width, scene.render.height);
    const ShaftsSettings& shafts = scene.lighting.shafts;

    ref::HazeReferenceParams hp;
    hp.camera = camera;
    hp.origin = {float(scene.grid.origin[0]), float(scene.grid.origin[1]), float(scene.grid.origin[2])};
    hp.voxelSize = float(scene.grid.voxelSize);
    hp.sun = scene.sun.DirectionAt(in.step);
    hp.sunRadiance = scene.sun.Radiance();
    hp.extinction = shafts.extinction;
    hp.g = shafts.g;
    hp.cloudSigma = scene.shade.sigma;
    hp.tiling = scene.grid.tiling;
    hp.threads = eval.Options().cpuThreads;
    auto reference = ref::RenderHazeReference(hp, in.grid, in.q);
    if (!reference) return MakeError("the haze reference: " + reference.error().message);

    // The shell counts without the falloff (which the reference does not have), then the scene's own setting.
    struct Setting {
        uint32_t shells;
        double falloffDeg;
        bool scene;
    };
    std::vector<Setting> settings;
    for (uint32_t count : kShaftsShellCounts) settings.push_back({count, 0.0, false});
    settings.push_back({shafts.shells, shafts.falloffDeg, true});
    json rows = json::array();
    const Extent3 columns{in.grid.nx, in.grid.ny, 1};
    for (const Setting& setting : settings)
        for (const OpenedBackend& slot : backends) {
            json row = {{"shells", setting.shells},
                        {"falloff_deg", setting.falloffDeg},
                        {"backend", slot.name},
                        {"scene", setting.scene}};
            if (!slot.backend) {
                row["status"] = "unavailable";
                row["detail"] = slot.reason;
                rows.push_back(row);
                continue;
            }
            Scene measured = scene;
            measured.lighting.shafts.shells = setting.shells;
            measured.lighting.shafts.falloffDeg = setting.falloffDeg;
            const ShaftsFrame frame = MakeSceneShaftsFrame(measured, camera, in.step);
            auto shells = ShellsImage(*slot.backend, frame, in.D, columns, eval.Measurement().repeats);
            if (!shells) {
                row["status"] = "failed";
                row["detail"] = shells.error().message;
                rows.push_back(row);
                continue;
            }
            const ImageErrorStats e = ImageErrors(shells->second, reference->image);
            row["status"] = "ok";
            row["time"] = TimeJson(shells->first);
            row["error"] = {{"max", e.pixel.max},
                            {"mean", e.pixel.mean},
                            {"p99", e.pixel.p99},
                            {"peak", e.peak},
                            {"psnr_db", e.psnr ? json(*e.psnr) : json(nullptr)}};
            rows.push_back(row);
        }
    return json{{"reference",
                 {{"step_voxels", hp.stepVoxels},
                  {"samples", reference->samples},
                  {"light_rays", reference->lightRays},
                  {"seconds", reference->seconds}}},
                {"rows", rows}};
}

report::Table ShaftsRowsTable(const json& rows) {
    using report::Column;
    report::Table table({Column("shells").Integer(), Column("falloff"), Column("backend"),
                         Column("time ms (q1-q3)").Unit("ms"),
                         Column("max").Real("%.3g"), Column("mean").Real("%.3g"), Column("p99").Real("%.3g"),
                         Column("PSNR dB").Real("%.2f")});
    for (const json& r : rows) {
        const double falloff = r["falloff_deg"].get<double>();
        std::vector<report::Cell> cells = {int64_t(r["shells"].get<uint32_t>()),
                                           falloff > 0 ? Fmt("%g deg", falloff) : std::string("none"),
                                           r["backend"].get<std::string>() + (r["scene"].get<bool>() ? " (scene)" : "")};
        if (r["status"] != "ok") {
            cells.push_back(r["status"].get<std::string>() + ": " + r.value("detail", std::string()));
            table.rows.push_back(std::move(cells));
            continue;
        }
        cells.push_back(TimeCell(r["time"]));
        AppendImageErrorCells(r["error"], cells);
        table.rows.push_back(std::move(cells));
    }
    return table;
}

}  // namespace cb
