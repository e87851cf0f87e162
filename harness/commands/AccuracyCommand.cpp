// `cloudbench accuracy` (docs/accuracy.md): every shade and shadow option of
// every backend measured against the exact (Embree) reference; writes
// accuracy.json and accuracy.md.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "core/plan/StageGraph.h"
#include "core/scene/SceneNames.h"
#include "core/stages/shade/Shade.h"
#include "harness/accuracy/AccuracyTransfer.h"
#include "harness/accuracy/ImageAccuracy.h"
#include "harness/accuracy/IsolatedMeasurement.h"
#include "harness/accuracy/Measurement.h"
#include "harness/accuracy/ReprojectionAccuracy.h"
#include "harness/accuracy/ShaftsAccuracy.h"
#include "harness/report/ReportTransfer.h"
#include "harness/run/RunTransfer.h"

namespace cb {
namespace {

using nlohmann::json;

// Each renderer's own settings that `accuracy` tries, from its descriptor: "  <name>: <settings>;" wrapped at 80
// columns, the last line ending with "; " and a newline.
std::string AccuracyVariantsHelp() {
    std::string text;
    for (Stage stage : RendererStages()) {
        const std::string_view help = Describe(stage).renderer->accuracyVariantsHelp;
        if (help.empty()) continue;
        std::string line = "  " + std::string(StageName(stage)) + ":";
        size_t start = 0;
        while (start <= help.size()) {
            size_t end = help.find(' ', start);
            if (end == std::string_view::npos) end = help.size();
            const std::string word = std::string(help.substr(start, end - start)) + (end == help.size() ? ";" : "");
            if (line.size() + 1 + word.size() > 80) {
                text += line + "\n";
                line = "   ";
            }
            line += " " + word;
            start = end + 1;
        }
        text += line + "\n";
    }
    return text;
}

const std::string kHelpText = R"(usage: cloudbench accuracy [SCENE] [options]

Simulates SCENE on the CPU to its last step, computes the exact references
T_ref (every voxel, from the point where the ray toward the sun leaves the
voxel) and G_ref (every ground cell) with Embree, and measures the shade and
shadow stages of every backend against them: the scene's settings, then each
option changed one at a time (shade: attenuation, filter, resolution, storage,
scattering; shadow: form). Prints per option and backend the median time with
quartiles and the max, mean and 99th-percentile |error| over all voxels and
over the voxels in cloud (q > 0) or ground cells under cloud (G_ref < 1), the
reference's own speed in rays per second, and writes DIR/accuracy.json and
DIR/accuracy.md.

With a renderer in the scene ()" +
                              RendererNames(", ") + R"()
it also renders the exact reference image (the ray march's kernel with exact
light toward the sun and the point light, a fine step, no early termination,
no jitter; with grid.tiling over the repeated volume) and measures
each renderer on each backend against it: the scene's settings, then each of
its own settings changed one at a time:
)" + AccuracyVariantsHelp() + R"(per-pixel error = max over channels of |C - C_ref|, with max, mean, p99 and
PSNR.

With temporal reprojection (march.reprojection.block > 1) it also runs the
scene twice in lock step on each backend, as it is and with every pixel
traced, and compares each step's ray-marched frame: PSNR per frame, its
median and the worst frame, beside render_march's median time a frame in
each run and the speed-up.

With shafts of light (lighting.shafts) it renders the exact single-scattering
haze and measures the light the shells add, at 4, 16 and 64 shells without
the falloff and at the scene's own setting, on each backend, with the pass's
time.

Options:
  --backend LIST     backends to measure (default: all built); unavailable ones
                     are reported, and a stage a backend lacks is listed as
                     unsupported; --backends is the same
  --repeat N         timed calls per measurement, after one warm-up (default 5)
  --switches         also cross the principal axis's 45-degree switches: error on
                     each side (1e-6 rad, 1e-3 rad, 1 degree) and the jump in T
  --reference-step X the exact reference render's step in voxel edges (default
                     0.125), for scenes with a renderer
  --steps N          number of steps (same as --set steps=N)
  --out DIR          output folder (default: out/<scene name>/accuracy)
  --set PATH=VALUE   override a scene field (see cloudbench help run)
  --threads N        CPU backend and reference threads (default: all)
  --cpu-isa ISA      CPU kernels' SIMD target: auto (default: the best here), scalar, sse4, avx2, avx512
  --vk-device DEV    Vulkan device: index or part of the name
  --quiet            no progress lines
)";
const std::string kHelp = kHelpText + GlOptionsHelp() + IsolationOptionsHelp();

// Every value of the stage's choice settings (its descriptor's) that differs from the scene's.
std::vector<std::vector<SceneOverride>> OptionVariants(const Scene& scene, Stage stage) {
    std::vector<std::vector<SceneOverride>> out;
    for (const ChoiceSetting& choice : Describe(stage).choices) {
        const std::string current = choice.current(scene);
        for (std::string& value : choice.values())
            if (value != current) out.push_back({{std::string(choice.path), std::move(value)}});
    }
    return out;
}

// Principal-axis switches.

struct SwitchCase {
    std::string name;
    double tieElevation, tieAzimuth;  // radians
    bool alongElevation;              // the angle that moves across the switch
};

// The z switch at the scene's azimuth (tan el = max(|cos az|, |sin az|)) and
// the x/y switch at azimuth 45 degrees and an elevation below the z switch.
std::vector<SwitchCase> SwitchCases(const Scene& scene) {
    constexpr double kDeg = std::numbers::pi / 180;
    const double az = scene.sun.azimuthDeg * kDeg;
    const double zTie = std::atan(std::max(std::fabs(std::cos(az)), std::fabs(std::sin(az))));
    const double xyElevation = std::min(scene.sun.elevationDeg * kDeg, 25 * kDeg);
    return {{"z / horizontal (elevation " + Fmt("%.4f", zTie / kDeg) + " deg at azimuth " +
                 Fmt("%.1f", scene.sun.azimuthDeg) + ")",
             zTie, az, true},
            {"x / y (azimuth 45 deg at elevation " + Fmt("%.1f", xyElevation / kDeg) + ")", xyElevation,
             std::numbers::pi / 4, false}};
}

std::string EpsilonText(double eps) {
    return eps < 1e-2 ? Fmt("%.0e", eps) + " rad" : Fmt("%.3g", eps * 180 / std::numbers::pi) + " deg";
}

const char* AxisName(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

// Each row and doc item has a key, its place in the order of one process
// measuring every backend: 3 per (switch, epsilon), side 0, side 1, jump.
struct SwitchResult {
    json doc = json::array();
    report::Table errors, jumps;
    std::vector<int> errorKeys, jumpKeys, docKeys;
};

// The tables' columns, without rows.
SwitchResult EmptySwitchResult() {
    SwitchResult out;
    out.errors = TextTable({"switch", "epsilon", "side", "axis", "backend"});
    for (auto& c : StatsColumns()) out.errors.columns.push_back(c);
    for (auto& c : StatsColumns(" (in cloud)")) out.errors.columns.push_back(c);
    out.jumps = TextTable({"switch", "epsilon", "axes", "backend"});
    for (const char* title : {"jump max|T+ - T-|", "T_ref jump", "a-priori bound"})
        out.jumps.columns.push_back(report::Column(title).Real("%.3g"));
    return out;
}

Result<SwitchResult> MeasureSwitches(Evaluator& eval, const Session& session, std::span<const OpenedBackend> backends) {
    constexpr double kDeg = std::numbers::pi / 180;
    const CommonOptions& options = session.Options();
    const Scene& base = session.GetScene();
    SwitchResult out = EmptySwitchResult();
    int key = 0;
    for (const SwitchCase& c : SwitchCases(base)) {
        for (double eps : {1e-6, 1e-3, 1.0 * kDeg}) {
            key += 3;
            std::map<std::string, std::vector<float>> T[2];  // per side, per backend
            std::vector<float> Tref[2];
            Vec3 sun[2];
            int axis[2];
            for (int side = 0; side < 2; ++side) {
                const double sign = side == 0 ? -1 : 1;
                const double el = c.alongElevation ? c.tieElevation + sign * eps : c.tieElevation;
                const double az = c.alongElevation ? c.tieAzimuth : c.tieAzimuth + sign * eps;
                const SceneOverride sunAt[] = {{"sun.elevation_deg", Fmt("%.17g", el / kDeg)},
                                               {"sun.azimuth_deg", Fmt("%.17g", az / kDeg)}};
                auto point = eval.Load(sunAt);
                if (!point) return std::unexpected(point.error());
                sun[side] = point->scene.sun.Direction();
                axis[side] = PrincipalAxis(sun[side]);
                Tref[side] = point->reference->T;
                for (const OpenedBackend& slot : backends) {
                    if (!slot.backend) continue;
                    StageAccuracy a = MeasureShade(*slot.backend, point->scene, *point->in, *point->reference, 0, true);
                    if (a.status != "ok") continue;
                    std::vector<report::Cell> cells = {c.name, EpsilonText(eps), side == 0 ? "-" : "+",
                                                       AxisName(axis[side]), slot.name};
                    for (auto& cell : StatsCells(a.all)) cells.push_back(cell);
                    for (auto& cell : StatsCells(a.subset)) cells.push_back(cell);
                    out.errors.rows.push_back(std::move(cells));
                    out.errorKeys.push_back(key + side);
                    out.docKeys.push_back(key + side);
                    out.doc.push_back({{"switch", c.name},
                                       {"epsilon_rad", eps},
                                       {"side", side == 0 ? "-" : "+"},
                                       {"axis", AxisName(axis[side])},
                                       {"backend", slot.name},
                                       {"error", {{"all", StatsJson(a.all)}, {"in_cloud", StatsJson(a.subset)}}}});
                    T[side][slot.name] = std::move(a.output);
                }
            }
            // The jump between the two sides, and its a-priori bound from the tie direction.
            const Vec3 tie = SunDirection(c.tieElevation, c.tieAzimuth);
            float qMax = 0;
            if (auto in = eval.Inputs(base, options.overrides))
                for (float v : (*in)->q) qMax = std::max(qMax, v);
            const ShadeParams params = MakeShadeParams(base);
            const double bound = SwitchSideBound(params, base.grid.size, sun[0], tie, axis[0], qMax) +
                                 SwitchSideBound(params, base.grid.size, sun[1], tie, axis[1], qMax);
            double refJump = 0;
            for (size_t v = 0; v < Tref[0].size(); ++v)
                refJump = std::max(refJump, std::fabs(double(Tref[0][v]) - double(Tref[1][v])));
            for (const auto& [name, lower] : T[0]) {
                auto upper = T[1].find(name);
                if (upper == T[1].end()) continue;
                double jump = 0;
                for (size_t v = 0; v < lower.size(); ++v)
                    jump = std::max(jump, std::fabs(double(lower[v]) - double(upper->second[v])));
                out.jumps.rows.push_back({c.name, EpsilonText(eps),
                                          std::string(AxisName(axis[0])) + " -> " + AxisName(axis[1]), name, jump,
                                          refJump, bound});
                out.jumpKeys.push_back(key + 2);
                out.docKeys.push_back(key + 2);
                out.doc.push_back({{"switch", c.name},
                                   {"epsilon_rad", eps},
                                   {"backend", name},
                                   {"axes", {AxisName(axis[0]), AxisName(axis[1])}},
                                   {"jump", jump},
                                   {"reference_jump", refJump},
                                   {"bound", bound}});
            }
        }
    }
    return out;
}

// The ray-start comparison's columns, without rows.
report::Table RayStartTable() {
    report::Table table = TextTable({"comparison", "backend"});
    for (auto& c : StatsColumns()) table.columns.push_back(c);
    return table;
}

// The scene's own shading against the reference counted from the voxel
// centre: how much the choice of the ray start matters.
Result<report::Section> RayStartSection(Evaluator& eval, const Scene& scene, std::span<const OpenedBackend> backends,
                                        json& doc) {
    auto in = eval.Inputs(scene, eval.Options().overrides);
    if (!in) return std::unexpected(in.error());
    auto exit = eval.Reference(scene, **in);
    if (!exit) return std::unexpected(exit.error());
    auto centre = eval.Reference(scene, **in, ref::RayStart::VoxelCentre);
    if (!centre) return std::unexpected(centre.error());
    const ErrorStats between = AbsoluteErrors((*exit)->T, (*centre)->T);
    report::Table table = RayStartTable();
    auto row = [](std::string comparison, std::string backend, const ErrorStats& e) {
        std::vector<report::Cell> cells = {std::move(comparison), std::move(backend)};
        for (auto& cell : StatsCells(e)) cells.push_back(cell);
        return cells;
    };
    table.rows.push_back(row("T_ref(voxel exit) vs T_ref(voxel centre)", "", between));
    for (const OpenedBackend& slot : backends) {
        if (!slot.backend) continue;
        StageAccuracy a = MeasureShade(*slot.backend, scene, **in, **centre, 0);
        if (a.status != "ok") continue;
        table.rows.push_back(row("scene's T vs T_ref(voxel centre)", slot.name, a.all));
        doc["voxel_centre_reference"][slot.name] = StatsJson(a.all);
    }
    doc["voxel_exit_vs_centre"] = StatsJson(between);
    return report::Section{"Reference ray start: voxel exit (default) vs voxel centre", {std::move(table)}};
}

// Prints a section as it is done (after a blank line) and keeps it for accuracy.md.
void Emit(report::Report& report, report::Section section) {
    std::printf("\n%s", report::RenderText(section).c_str());
    report.sections.push_back(std::move(section));
}

// accuracy's own options (docs/accuracy.md): --repeat, --reference-step and --switches.
struct AccuracyOptions : MeasurementOptions {
    bool switches = false;  // also the jumps at each option's switching points
};

int Accuracy(const CommonOptions& options, const AccuracyOptions& own) {
    auto session = Session::Open(options, "accuracy");
    if (!session) return session.error();
    const Scene& scene = (*session)->GetScene();
    const bool images = RunsARenderer(scene.stages);
    const bool reprojects = scene.stages.Has(Stage::RenderMarch) && scene.march.reprojectionBlock > 1;
    if (!scene.stages.Has(Stage::Shade) && !scene.stages.Has(Stage::Shadow) && !images) {
        std::string renderers;
        for (Stage stage : RendererStages())
            renderers += (renderers.empty() ? "\"" : ", \"") + std::string(StageName(stage)) + "\"";
        std::fprintf(stderr, "%s: stages: accuracy needs \"shade\", \"shadow\" or a renderer (%s)\n",
                     scene.path.c_str(), renderers.c_str());
        return kExitBadScene;
    }
    if (!(*session)->MakeOutDir()) return kExitFailed;
    const std::vector<std::string> names = (*session)->RequestedBackends(BuiltBackends());

    std::printf(
        "accuracy of scene %s (%ux%ux%u) at step %u against the exact reference (Embree; T_ref from each "
        "voxel's exit point toward the sun)\n",
        scene.name.c_str(), scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz, scene.steps - 1);
    // Each backend measures every setting, the ray start and the switches in a
    // process of its own (harness/accuracy/IsolatedMeasurement.h); the parent merges.
    std::vector<PlannedSetting> plan;
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        if (!scene.stages.Has(stage)) continue;
        std::vector<std::vector<SceneOverride>> settings = {{}};
        for (auto& v : OptionVariants(scene, stage)) settings.push_back(v);
        for (const auto& setting : settings) plan.push_back({setting, {stage}});
    }
    auto more = [&](Evaluator& eval, std::span<const OpenedBackend> backends) -> Result<json> {
        json extra = json::object();
        if (scene.stages.Has(Stage::Shade)) {
            json doc = json::object();
            auto section = RayStartSection(eval, scene, backends, doc);
            if (!section) return std::unexpected(section.error());
            json rows = json::array();
            for (const auto& cells : std::get<report::Table>(section->blocks[0]).rows)
                rows.push_back(transfer::ToJson(cells));
            extra["ray_start"] = {{"rows", rows}, {"doc", doc}};
        }
        if (own.switches && scene.stages.Has(Stage::Shade)) {
            auto sw = MeasureSwitches(eval, **session, backends);
            if (!sw) return MakeError("switches: " + sw.error().message);
            json errors = json::array(), jumps = json::array(), items = json::array();
            for (size_t n = 0; n < sw->errors.rows.size(); ++n)
                errors.push_back({sw->errorKeys[n], transfer::ToJson(sw->errors.rows[n])});
            for (size_t n = 0; n < sw->jumps.rows.size(); ++n)
                jumps.push_back({sw->jumpKeys[n], transfer::ToJson(sw->jumps.rows[n])});
            for (size_t n = 0; n < sw->doc.size(); ++n) items.push_back({sw->docKeys[n], sw->doc[n]});
            extra["switches"] = {{"errors", errors}, {"jumps", jumps}, {"doc", items}};
        }
        if (images) {
            auto rows = MeasureImages(eval, **session, backends);
            if (!rows) return MakeError("images: " + rows.error().message);
            extra["images"] = std::move(*rows);
        }
        if (scene.lighting.shafts.on) {
            auto shafts = MeasureShafts(eval, backends);
            if (!shafts) return MakeError("shafts: " + shafts.error().message);
            extra["shafts"] = std::move(*shafts);
        }
        if (reprojects)
            for (const OpenedBackend& slot : backends) {
                if (!slot.backend) continue;
                // A backend that cannot reproject says why in its row; the other measurements stand.
                auto rows = MeasureReprojection(*slot.backend, slot.name, scene);
                extra["reprojection"] =
                    rows ? std::move(*rows) : json::array({{{"backend", slot.name}, {"error", rows.error().message}}});
            }
        return extra;
    };
    auto parts = MeasureEachBackend(**session, own, names, plan, more);
    if (!parts) {
        std::fprintf(stderr, "accuracy: %s\n", parts.error().message.c_str());
        return kExitFailed;
    }
    if (std::ranges::none_of(*parts, [](const BackendMeasurement& p) { return p.available; })) return kExitNoBackend;
    const bool anyCrashed =
        std::ranges::any_of(*parts, [](const BackendMeasurement& p) { return p.failure.has_value(); });
    std::vector<Row> rows = MergeRows(scene, plan, *parts);

    json doc = {{"format", "cloudbench-accuracy/1"},
                {"scene", scene.name},
                {"grid", {scene.grid.size.nx, scene.grid.size.ny, scene.grid.size.nz}},
                {"step", scene.steps - 1},
                {"reference_start", "voxel-exit"},
                {"repeats", own.repeats},
                {"rows", json::array()}};
    report::Report report("Accuracy of " + scene.name);
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        report::Table table(ErrorColumns({"option"}, stage));
        for (const Row& r : rows)
            if (r.stage == stage) {
                std::vector<report::Cell> cells = {SettingsLabel(r.settings)};
                for (auto& cell : RowCells(r)) cells.push_back(std::move(cell));
                table.rows.push_back(std::move(cells));
                doc["rows"].push_back(RowJson(r));
            }
        if (table.rows.empty()) continue;
        Emit(report, {stage == Stage::Shade ? "shade: |T - T_ref| over all voxels and voxels with q > 0"
                                            : "shadow: |G - G_ref| over all ground cells and cells with G_ref < 1",
                      {std::move(table)}});
    }
    // The ray start: the reference-against-reference row once, then each backend's.
    report::Table rayStart = RayStartTable();
    bool anyRayStart = false;
    for (const BackendMeasurement& part : *parts) {
        if (!part.extra.contains("ray_start")) continue;
        const json& r = part.extra["ray_start"];
        for (size_t n = anyRayStart ? 1 : 0; n < r["rows"].size(); ++n)
            rayStart.rows.push_back(transfer::CellsFromJson(r["rows"][n]));
        if (r["doc"].contains("voxel_centre_reference"))
            for (const auto& [name, stats] : r["doc"]["voxel_centre_reference"].items())
                doc["voxel_centre_reference"][name] = stats;
        if (!anyRayStart) doc["voxel_exit_vs_centre"] = r["doc"]["voxel_exit_vs_centre"];
        anyRayStart = true;
    }
    if (anyRayStart) Emit(report, {"Reference ray start: voxel exit (default) vs voxel centre", {std::move(rayStart)}});
    if (own.switches && scene.stages.Has(Stage::Shade)) {
        // Rows by key, then by backend (the parts' order): a stable sort of the parts' rows in turn.
        SwitchResult sw = EmptySwitchResult();
        auto merged = [&](const char* name) {
            std::vector<std::pair<int, json>> items;
            for (const BackendMeasurement& part : *parts)
                if (part.extra.contains("switches"))
                    for (const json& item : part.extra["switches"][name])
                        items.emplace_back(item[0].get<int>(), item[1]);
            std::ranges::stable_sort(items, {}, &std::pair<int, json>::first);
            return items;
        };
        for (auto& [key, cells] : merged("errors")) sw.errors.rows.push_back(transfer::CellsFromJson(cells));
        for (auto& [key, cells] : merged("jumps")) sw.jumps.rows.push_back(transfer::CellsFromJson(cells));
        for (auto& [key, item] : merged("doc")) sw.doc.push_back(item);
        Emit(report, {"Principal-axis switches: error on each side", {std::move(sw.errors)}});
        Emit(report, {"Jump at the switch", {std::move(sw.jumps)}});
        doc["switches"] = sw.doc;
    }
    if (images) {
        // Rows by (renderer, setting) in the order they first appear, then by backend (the parts' order);
        // a backend without a renderer has its one "unsupported" row only.
        json imageRows = json::array(), imageRefs = json::array();
        std::vector<std::string> keys;
        auto keyOf = [](const json& r) {
            return r["renderer"].get<std::string>() + "|" + r["label"].get<std::string>();
        };
        for (const BackendMeasurement& part : *parts)
            if (part.extra.contains("images"))
                for (const json& r : part.extra["images"]["rows"])
                    if (std::ranges::find(keys, keyOf(r)) == keys.end()) keys.push_back(keyOf(r));
        for (const std::string& key : keys)
            for (const BackendMeasurement& part : *parts)
                if (part.extra.contains("images"))
                    for (const json& r : part.extra["images"]["rows"])
                        if (keyOf(r) == key) imageRows.push_back(r);
        // A backend that did not open or whose process died: one row per renderer with why.
        for (const BackendMeasurement& part : *parts) {
            if (part.extra.contains("images")) {
                if (imageRefs.empty()) imageRefs = part.extra["images"]["references"];
                continue;
            }
            for (Stage r : RendererStages())
                if (scene.stages.Has(r))
                    imageRows.push_back({{"renderer", StageName(r)},
                                         {"backend", part.name},
                                         {"settings", json::object()},
                                         {"label", "(scene)"},
                                         {"reference_phase", ""},
                                         {"status", part.failure ? part.failure->status : part.status},
                                         {"detail", part.failure ? part.failure->message : part.reason}});
        }
        doc["image_rows"] = imageRows;
        doc["image_references"] = imageRefs;
        doc["reference_step_voxels"] = own.referenceStep;
        Emit(report, {"images: per-pixel max over channels of |C - C_ref| (linear HDR) against the exact reference "
                      "render, and PSNR (peak: the reference's largest value)",
                      {ImageRowsTable(imageRows)}});
        Emit(report, {"Reference render", {ImageReferenceTable(imageRefs)}});
    }
    if (reprojects) {
        json rows = json::array();
        for (const BackendMeasurement& part : *parts)
            if (part.extra.contains("reprojection"))
                for (const json& r : part.extra["reprojection"]) rows.push_back(r);
        doc["reprojection"] = rows;
        Emit(report, {"Temporal reprojection: each step's ray-marched frame against the full frame (every pixel "
                      "traced) along the scene's frames, and render_march's median time a frame in each run",
                      {ReprojectionTable(rows)}});
    }
    if (scene.lighting.shafts.on) {
        json rows = json::array();
        for (const BackendMeasurement& part : *parts)
            if (part.extra.contains("shafts")) {
                if (!doc.contains("shafts_reference")) doc["shafts_reference"] = part.extra["shafts"]["reference"];
                for (const json& r : part.extra["shafts"]["rows"]) rows.push_back(r);
            }
        // By setting (the scene's last), then by backend (the parts' order).
        std::stable_sort(rows.begin(), rows.end(), [](const json& a, const json& b) {
            return std::pair(a["scene"].get<bool>(), a["shells"].get<uint32_t>()) <
                   std::pair(b["scene"].get<bool>(), b["shells"].get<uint32_t>());
        });
        doc["shafts"] = rows;
        Emit(report, {"Shafts of light: the shells' added light against the exact single-scattering haze (per-pixel "
                      "max over channels, linear HDR; PSNR's peak the reference's largest value) and the pass's time",
                      {ShaftsRowsTable(rows)}});
    }
    doc["references"] = ReferencesJson(FirstRecords(*parts), options.cpuThreads);
    Emit(report, {"Reference speed", {ReferenceSpeedTable(FirstRecords(*parts))}});
    doc["report"] = report::RenderJson(report);

    const std::string jsonPath = (*session)->OutDir() + "/accuracy.json";
    const std::string mdPath = (*session)->OutDir() + "/accuracy.md";
    Status written = (*session)->WriteJson(jsonPath, doc);
    if (written) written = Session::WriteText(mdPath, report::RenderMarkdown(report));
    if (!written) {
        std::fprintf(stderr, "%s\n", written.error().message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s %s\n", jsonPath.c_str(), mdPath.c_str());
    return anyCrashed ? kExitFailed : kExitOk;
}

const CommandRegistration kRegistration({
    .name = "accuracy",
    .summary = "Measure every shade and shadow option against the exact (Embree) reference",
    .help = kHelp,
    .helpOrder = 4,
    .extraOptions = WithIsolationOptions({RepeatOption(), FlagOption("--switches", &AccuracyOptions::switches),
                                          ReferenceStepOption()}),
    .makeOptions = MakeOwnOptions<AccuracyOptions>,
    .run = RunWith(Accuracy),
});

}  // namespace
}  // namespace cb
