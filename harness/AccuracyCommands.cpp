// The accuracy commands (docs/cli.md, docs/accuracy.md): `accuracy`, `sweep`
// and `dump --reference`. The inputs of the lighting stages come from the CPU
// simulation of the scene; every backend's shade and shadow stage is fed the
// same q and D, timed, and compared with the Embree reference.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>

#include "core/Npy.h"
#include "core/SceneNames.h"
#include "harness/Accuracy.h"
#include "harness/Commands.h"
#include "harness/Simulation.h"
#include "harness/StageParams.h"

namespace cb {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// ---- Output helpers ------------------------------------------------------------

std::string Fmt(const char* format, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, value);
    return buffer;
}
std::string Err(double e) { return Fmt("%.3g", e); }
std::string TimeText(const Summary& s) {
    return Fmt("%.3f", s.median) + " (" + Fmt("%.3f", s.q1) + "-" + Fmt("%.3f", s.q3) + ")";
}

// A pipe table: Markdown, and readable on a terminal (columns padded).
std::string Table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
    std::vector<size_t> width(header.size(), 3);
    for (size_t c = 0; c < header.size(); ++c) width[c] = std::max(width[c], header[c].size());
    for (const auto& row : rows)
        for (size_t c = 0; c < row.size() && c < width.size(); ++c) width[c] = std::max(width[c], row[c].size());
    auto line = [&](const std::vector<std::string>& cells) {
        std::string out = "|";
        for (size_t c = 0; c < width.size(); ++c) {
            const std::string cell = c < cells.size() ? cells[c] : "";
            out += " " + cell + std::string(width[c] - cell.size(), ' ') + " |";
        }
        return out + "\n";
    };
    std::string out = line(header) + "|";
    for (size_t c = 0; c < width.size(); ++c) out += std::string(width[c] + 2, '-') + "|";
    out += "\n";
    for (const auto& row : rows) out += line(row);
    return out;
}

json StatsJson(const ErrorStats& e) {
    return {{"count", e.count}, {"max", e.max}, {"mean", e.mean}, {"p99", e.p99}, {"worst_index", e.worst}};
}
json TimeJson(const Summary& s) {
    return {{"median_ms", s.median}, {"q1_ms", s.q1},   {"q3_ms", s.q3},
            {"min_ms", s.min},       {"max_ms", s.max}, {"count", s.count}};
}

Status WriteText(const std::string& path, const std::string& text) {
    std::ofstream file(path);
    file << text;
    if (!file) return MakeError(path + ": cannot write");
    return {};
}

// ---- Backends, inputs and references, computed once each ---------------------

struct BackendSlot {
    std::string name;
    std::unique_ptr<Backend> backend;  // null when unavailable
    std::string error;
};

std::vector<BackendSlot> OpenBackends(const CommonOptions& options) {
    std::vector<BackendSlot> slots;
    for (const std::string& name : options.backends.empty() ? BuiltBackends() : options.backends) {
        BackendSlot slot{name, nullptr, ""};
        auto backend = CreateBackend(name, options.Backend());
        if (backend)
            slot.backend = std::move(*backend);
        else {
            slot.error = backend.error().message;
            std::fprintf(stderr, "backend %s unavailable: %s\n", name.c_str(), slot.error.c_str());
        }
        slots.push_back(std::move(slot));
    }
    return slots;
}

// Makes the output folder and opens the backends; the exit code when the
// folder cannot be made or no backend is available, nullopt to go on.
std::optional<int> OpenOutputAndBackends(const CommonOptions& options, const std::string& outDir,
                                         std::vector<BackendSlot>& backends) {
    if (Status s = MakeOutDir(outDir); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    backends = OpenBackends(options);
    for (const BackendSlot& b : backends)
        if (b.backend) return std::nullopt;
    return kExitNoBackend;
}

// Paths whose value changes only the lighting stages, not q or D.
bool LightingOnly(const std::string& path) {
    for (const char* prefix : {"shade", "shadow", "sun", "phase", "render", "lighting", "description"})
        if (path == prefix || path.starts_with(std::string(prefix) + ".")) return true;
    return false;
}

struct ReferenceRecord {
    std::string key;
    ref::TraceStats tStats, gStats;
    double buildSeconds = 0;
    size_t primitives = 0;
};

class Evaluator {
  public:
    Evaluator(const CommonOptions& options, ref::RayStart start) : mOptions(options), mStart(start) {}

    // q and D for a scene loaded with `overrides` (cached by the overrides that can change them).
    Result<const LightingInputs*> Inputs(const Scene& scene, const std::vector<SceneOverride>& overrides) {
        std::string key;
        for (const SceneOverride& o : overrides)
            if (!LightingOnly(o.path)) key += o.path + "=" + o.value + ";";
        auto it = mInputs.find(key);
        if (it == mInputs.end()) {
            if (!mOptions.quiet)
                std::fprintf(stderr, "simulating %u steps of %s%s%s\n", scene.steps, scene.name.c_str(),
                             key.empty() ? "" : " with ", key.c_str());
            auto in = SimulateLightingInputs(scene, mOptions.cpuThreads);
            if (!in) return std::unexpected(in.error());
            KeepOnlyLast(mInputs, mLastKey);
            it = mInputs.emplace(key, std::move(*in)).first;
        }
        mLastKey = key;
        return &it->second;
    }

    // The reference for the last Inputs() and the scene's sun, sigma and h.
    Result<const ReferenceResult*> Reference(const Scene& scene, const LightingInputs& in, ref::RayStart start) {
        const Vec3 s = scene.sun.Direction();
        const std::string key = mLastKey + "|sun " + Fmt("%.9g", s[0]) + " " + Fmt("%.9g", s[1]) + " " +
                                Fmt("%.9g", s[2]) + " sigma " + Fmt("%.17g", scene.shade.sigma) + " h " +
                                Fmt("%.17g", scene.grid.voxelSize) + " " + ref::RayStartName(start);
        // What a reader needs: the inputs that differ from the scene, the sun, the start.
        std::string label;
        for (size_t a = 0, b; a < mLastKey.size(); a = b + 1) {
            b = std::min(mLastKey.find(';', a), mLastKey.size());
            const std::string item = mLastKey.substr(a, b - a);
            if (!item.starts_with("warmup_steps=")) label += item + ", ";
        }
        label += "sun el " + Fmt("%.6f", scene.sun.elevationDeg) + " az " + Fmt("%.6f", scene.sun.azimuthDeg) +
                 ", from the " + ref::RayStartName(start);
        auto it = mReferences.find(key);
        if (it == mReferences.end()) {
            auto r = ComputeReference(scene, in, start, mOptions.cpuThreads);
            if (!r) return std::unexpected(r.error());
            ReferenceRecord rec{label, r->tStats, r->gStats, r->buildSeconds, r->primitives};
            if (!mOptions.quiet)
                std::fprintf(stderr,
                             "reference for %s: %zu boxes built in %.3f s; T_ref %llu rays in %.3f s (%.2f M rays/s), "
                             "G_ref %llu rays in %.3f s\n",
                             label.c_str(), rec.primitives, rec.buildSeconds, (unsigned long long)rec.tStats.rays,
                             rec.tStats.seconds, rec.tStats.RaysPerSecond() / 1e6, (unsigned long long)rec.gStats.rays,
                             rec.gStats.seconds);
            mRecords.push_back(rec);
            KeepOnlyLast(mReferences, mLastReference);
            it = mReferences.emplace(key, std::move(*r)).first;
        }
        mLastReference = key;
        return &it->second;
    }
    Result<const ReferenceResult*> Reference(const Scene& scene, const LightingInputs& in) {
        return Reference(scene, in, mStart);
    }

    // The scene at scenePath with `overrides`, its inputs and its reference.
    struct Point {
        Scene scene;
        const LightingInputs* in = nullptr;
        const ReferenceResult* reference = nullptr;
    };
    Result<Point> Load(const std::string& scenePath, const std::vector<SceneOverride>& overrides) {
        auto scene = LoadScene(scenePath, overrides);
        if (!scene) return std::unexpected(scene.error());
        auto in = Inputs(*scene, overrides);
        if (!in) return std::unexpected(in.error());
        auto reference = Reference(*scene, **in);
        if (!reference) return std::unexpected(reference.error());
        return Point{std::move(*scene), *in, *reference};
    }

    const std::vector<ReferenceRecord>& Records() const { return mRecords; }

  private:
    // Bounds memory (a thesis-sized reference is about 11 MB): past kKept
    // entries, all but the last one returned are dropped, so the pointer the
    // caller still holds from the previous call stays valid.
    static constexpr size_t kKept = 8;
    template <typename Map>
    static void KeepOnlyLast(Map& map, const std::string& last) {
        if (map.size() < kKept) return;
        for (auto it = map.begin(); it != map.end();) it = it->first == last ? std::next(it) : map.erase(it);
    }

    const CommonOptions& mOptions;
    ref::RayStart mStart;
    std::string mLastReference;
    std::map<std::string, LightingInputs> mInputs;
    std::map<std::string, ReferenceResult> mReferences;
    std::vector<ReferenceRecord> mRecords;
    std::string mLastKey;
};

json ReferencesJson(const std::vector<ReferenceRecord>& records, int threads) {
    json out = json::array();
    for (const ReferenceRecord& r : records)
        out.push_back(
            {{"inputs", r.key},
             {"boxes", r.primitives},
             {"build_s", r.buildSeconds},
             {"threads", threads},
             {"T_ref",
              {{"rays", r.tStats.rays}, {"seconds", r.tStats.seconds}, {"rays_per_s", r.tStats.RaysPerSecond()}}},
             {"G_ref",
              {{"rays", r.gStats.rays}, {"seconds", r.gStats.seconds}, {"rays_per_s", r.gStats.RaysPerSecond()}}}});
    return out;
}

// One measured row: a setting (list of overrides) x backend x stage.
struct Row {
    std::vector<SceneOverride> settings;
    std::string backend;
    Stage stage = Stage::Shade;
    StageAccuracy result;
    bool pareto = false;
};

std::string SettingsLabel(const std::vector<SceneOverride>& settings) {
    if (settings.empty()) return "(scene)";
    std::string out;
    for (const SceneOverride& o : settings) out += (out.empty() ? "" : " ") + o.path + "=" + o.value;
    return out;
}

json RowJson(const Row& r) {
    json settings = json::object();
    for (const SceneOverride& o : r.settings) settings[o.path] = o.value;
    json j = {
        {"settings", settings}, {"backend", r.backend}, {"stage", StageName(r.stage)}, {"status", r.result.status}};
    if (!r.result.detail.empty()) j["detail"] = r.result.detail;
    if (r.result.status == "ok") {
        j["time"] = TimeJson(r.result.timeMs);
        j["error"] = {{"all", StatsJson(r.result.all)},
                      {r.stage == Stage::Shade ? "in_cloud" : "under_cloud", StatsJson(r.result.subset)}};
    }
    return j;
}

// Measures `stages` of one setting on every backend.
Status MeasureSetting(Evaluator& eval, const std::string& scenePath, const CommonOptions& options,
                      const std::vector<SceneOverride>& setting, std::span<const Stage> stages,
                      std::vector<BackendSlot>& backends, std::vector<Row>& rows) {
    std::vector<SceneOverride> all = options.overrides;
    all.insert(all.end(), setting.begin(), setting.end());
    auto point = eval.Load(scenePath, all);
    if (!point) return std::unexpected(point.error());
    const Scene& scene = point->scene;
    for (Stage stage : stages) {
        if (!scene.stages.Has(stage)) continue;
        for (BackendSlot& slot : backends) {
            Row row{setting, slot.name, stage, {}, false};
            if (!slot.backend)
                row.result = {"unavailable", slot.error, {}, {}, {}, {}};
            else if (stage == Stage::Shade)
                row.result = MeasureShade(*slot.backend, scene, *point->in, *point->reference, options.repeats);
            else
                row.result = MeasureShadow(*slot.backend, scene, *point->in, *point->reference, options.repeats);
            if (row.result.status != "ok" && !options.quiet)
                std::fprintf(stderr, "%s %s %s: %s: %s\n", slot.name.c_str(), std::string(StageName(stage)).c_str(),
                             SettingsLabel(setting).c_str(), row.result.status.c_str(), row.result.detail.c_str());
            rows.push_back(std::move(row));
        }
    }
    return {};
}

std::vector<std::string> RowCells(const Row& r, bool withLabel) {
    std::vector<std::string> cells;
    if (withLabel) cells.push_back(SettingsLabel(r.settings));
    cells.push_back(r.backend);
    if (r.result.status != "ok") {
        cells.push_back(r.result.status + ": " + r.result.detail);
        return cells;
    }
    const StageAccuracy& a = r.result;
    for (const std::string& s : {TimeText(a.timeMs), Err(a.all.max), Err(a.all.mean), Err(a.all.p99), Err(a.subset.max),
                                 Err(a.subset.mean), Err(a.subset.p99)})
        cells.push_back(s);
    return cells;
}

// Values of each shade and shadow option that differ from the scene's.
std::vector<std::vector<SceneOverride>> OptionVariants(const Scene& scene, Stage stage) {
    std::vector<std::vector<SceneOverride>> out;
    auto add = [&](const char* path, std::initializer_list<const char*> values, const std::string& current) {
        for (const char* v : values)
            if (current != v) out.push_back({{path, v}});
    };
    // A choice's names come from the scene's own table (core/SceneNames.h), in its order.
    auto addNames = [&](const char* path, const auto& names, auto current) {
        for (const auto& [name, value] : names)
            if (value != current) out.push_back({{path, std::string(name)}});
    };
    if (stage == Stage::Shade) {
        const ShadeSettings& s = scene.shade;
        addNames("shade.attenuation", kAttenuationKindNames, s.attenuation);
        addNames("shade.filter", kSampleFilterNames, s.filter);
        add("shade.resolution", {"1", "2", "4"}, std::to_string(s.resolution));
        addNames("shade.storage", kStorageFormatNames, s.storage);
        add("shade.scattering.enabled", {"false", "true"}, s.scattering ? "true" : "false");
    } else {
        addNames("shadow.form", kAttenuationKindNames, scene.shadow.form);
    }
    return out;
}

const std::vector<std::string> kErrorHeader = {"time ms (q1-q3)", "max", "mean", "p99", "max", "mean", "p99"};

std::vector<std::string> Header(std::initializer_list<std::string> first, Stage stage) {
    std::vector<std::string> h(first);
    h.insert(h.end(), kErrorHeader.begin(), kErrorHeader.end());
    // The last three are the subset's.
    const std::string subset = stage == Stage::Shade ? "in cloud" : "under cloud";
    for (size_t c = h.size() - 3; c < h.size(); ++c) h[c] += " (" + subset + ")";
    return h;
}

// ---- Principal-axis switches ---------------------------------------------------

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

struct SwitchResult {
    json doc = json::array();
    std::string errorsTable, jumpTable;
};

Result<SwitchResult> MeasureSwitches(Evaluator& eval, const std::string& scenePath, const CommonOptions& options,
                                     std::vector<BackendSlot>& backends) {
    constexpr double kDeg = std::numbers::pi / 180;
    auto base = LoadScene(scenePath, options.overrides);
    if (!base) return std::unexpected(base.error());
    SwitchResult out;
    std::vector<std::vector<std::string>> errorRows, jumpRows;
    for (const SwitchCase& c : SwitchCases(*base)) {
        for (double eps : {1e-6, 1e-3, 1.0 * kDeg}) {
            std::map<std::string, std::vector<float>> T[2];  // per side, per backend
            std::vector<float> Tref[2];
            Vec3 sun[2];
            int axis[2];
            for (int side = 0; side < 2; ++side) {
                const double sign = side == 0 ? -1 : 1;
                const double el = c.alongElevation ? c.tieElevation + sign * eps : c.tieElevation;
                const double az = c.alongElevation ? c.tieAzimuth : c.tieAzimuth + sign * eps;
                std::vector<SceneOverride> all = options.overrides;
                all.push_back({"sun.elevation_deg", Fmt("%.17g", el / kDeg)});
                all.push_back({"sun.azimuth_deg", Fmt("%.17g", az / kDeg)});
                auto point = eval.Load(scenePath, all);
                if (!point) return std::unexpected(point.error());
                sun[side] = point->scene.sun.Direction();
                axis[side] = PrincipalAxis(sun[side]);
                Tref[side] = point->reference->T;
                for (BackendSlot& slot : backends) {
                    if (!slot.backend) continue;
                    StageAccuracy a = MeasureShade(*slot.backend, point->scene, *point->in, *point->reference, 0, true);
                    if (a.status != "ok") continue;
                    errorRows.push_back({c.name, EpsilonText(eps), side == 0 ? "-" : "+", AxisName(axis[side]),
                                         slot.name, Err(a.all.max), Err(a.all.mean), Err(a.all.p99), Err(a.subset.max),
                                         Err(a.subset.mean), Err(a.subset.p99)});
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
            if (auto in = eval.Inputs(*base, options.overrides))
                for (float v : (*in)->q) qMax = std::max(qMax, v);
            const ShadeParams params = MakeShadeParams(*base);
            const double bound = SwitchSideBound(params, base->grid.size, sun[0], tie, axis[0], qMax) +
                                 SwitchSideBound(params, base->grid.size, sun[1], tie, axis[1], qMax);
            double refJump = 0;
            for (size_t v = 0; v < Tref[0].size(); ++v)
                refJump = std::max(refJump, std::fabs(double(Tref[0][v]) - double(Tref[1][v])));
            for (const auto& [name, lower] : T[0]) {
                auto upper = T[1].find(name);
                if (upper == T[1].end()) continue;
                double jump = 0;
                for (size_t v = 0; v < lower.size(); ++v)
                    jump = std::max(jump, std::fabs(double(lower[v]) - double(upper->second[v])));
                jumpRows.push_back({c.name, EpsilonText(eps),
                                    std::string(AxisName(axis[0])) + " -> " + AxisName(axis[1]), name, Err(jump),
                                    Err(refJump), Err(bound)});
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
    out.errorsTable = Table({"switch", "epsilon", "side", "axis", "backend", "max", "mean", "p99", "max (in cloud)",
                             "mean (in cloud)", "p99 (in cloud)"},
                            errorRows);
    out.jumpTable =
        Table({"switch", "epsilon", "axes", "backend", "jump max|T+ - T-|", "T_ref jump", "a-priori bound"}, jumpRows);
    return out;
}

std::string DefaultOut(const CommonOptions& options, const Scene& scene, const char* what) {
    return options.outDir.empty() ? "out/" + scene.name + "/" + what : options.outDir;
}

}  // namespace

// ---- accuracy --------------------------------------------------------------------

int AccuracyCommand(const CommonOptions& options) {
    const std::string scenePath = ResolveScenePath(options.scene);
    auto scene = LoadScene(scenePath, options.overrides);
    if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().message.c_str());
        return kExitBadScene;
    }
    if (!scene->stages.Has(Stage::Shade) && !scene->stages.Has(Stage::Shadow)) {
        std::fprintf(stderr, "%s: stages: accuracy needs \"shade\" or \"shadow\"\n", scene->path.c_str());
        return kExitBadScene;
    }
    const std::string outDir = DefaultOut(options, *scene, "accuracy");
    std::vector<BackendSlot> backends;
    if (std::optional<int> exitCode = OpenOutputAndBackends(options, outDir, backends)) return *exitCode;

    Evaluator eval(options, ref::RayStart::VoxelExit);
    std::vector<Row> rows;
    std::string md = "# Accuracy of " + scene->name + "\n\n";
    std::printf(
        "accuracy of scene %s (%ux%ux%u) at step %u against the exact reference (Embree; T_ref from each "
        "voxel's exit point toward the sun)\n",
        scene->name.c_str(), scene->grid.size.nx, scene->grid.size.ny, scene->grid.size.nz, scene->steps - 1);
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        if (!scene->stages.Has(stage)) continue;
        const Stage only[] = {stage};
        std::vector<std::vector<SceneOverride>> settings = {{}};
        for (auto& v : OptionVariants(*scene, stage)) settings.push_back(v);
        for (const auto& setting : settings)
            if (Status s = MeasureSetting(eval, scenePath, options, setting, only, backends, rows); !s) {
                std::fprintf(stderr, "accuracy: %s: %s\n", SettingsLabel(setting).c_str(), s.error().message.c_str());
                return kExitFailed;
            }
    }
    json doc = {{"format", "cloudbench-accuracy/1"},
                {"scene", scene->name},
                {"grid", {scene->grid.size.nx, scene->grid.size.ny, scene->grid.size.nz}},
                {"step", scene->steps - 1},
                {"reference_start", "voxel-exit"},
                {"repeats", options.repeats},
                {"rows", json::array()}};
    for (Stage stage : {Stage::Shade, Stage::Shadow}) {
        std::vector<std::vector<std::string>> cells;
        for (const Row& r : rows)
            if (r.stage == stage) {
                cells.push_back(RowCells(r, true));
                doc["rows"].push_back(RowJson(r));
            }
        if (cells.empty()) continue;
        const std::string title = stage == Stage::Shade ? "shade: |T - T_ref| over all voxels and voxels with q > 0"
                                                        : "shadow: |G - G_ref| over all ground cells and cells with "
                                                          "G_ref < 1";
        const std::string table = Table(Header({"option", "backend"}, stage), cells);
        std::printf("\n%s\n%s", title.c_str(), table.c_str());
        md += "## " + title + "\n\n" + table + "\n";
    }

    // How much the choice of the ray start matters: the scene's own shading
    // against the reference counted from the voxel centre.
    if (scene->stages.Has(Stage::Shade)) {
        auto in = eval.Inputs(*scene, options.overrides);
        auto exit = in ? eval.Reference(*scene, **in) : Result<const ReferenceResult*>(std::unexpected(in.error()));
        auto centre = in ? eval.Reference(*scene, **in, ref::RayStart::VoxelCentre)
                         : Result<const ReferenceResult*>(std::unexpected(in.error()));
        if (!exit || !centre) {
            std::fprintf(stderr, "accuracy: %s\n", (!exit ? exit.error() : centre.error()).message.c_str());
            return kExitFailed;
        }
        const ErrorStats between = AbsoluteErrors((*exit)->T, (*centre)->T);
        std::vector<std::vector<std::string>> cells = {
            {"T_ref(voxel exit) vs T_ref(voxel centre)", "", Err(between.max), Err(between.mean), Err(between.p99)}};
        for (BackendSlot& slot : backends) {
            if (!slot.backend) continue;
            StageAccuracy a = MeasureShade(*slot.backend, *scene, **in, **centre, 0);
            if (a.status != "ok") continue;
            cells.push_back(
                {"scene's T vs T_ref(voxel centre)", slot.name, Err(a.all.max), Err(a.all.mean), Err(a.all.p99)});
            doc["voxel_centre_reference"][slot.name] = StatsJson(a.all);
        }
        doc["voxel_exit_vs_centre"] = StatsJson(between);
        const std::string table = Table({"comparison", "backend", "max", "mean", "p99"}, cells);
        std::printf("\nreference ray start: voxel exit (default) vs voxel centre\n%s", table.c_str());
        md += "## Reference ray start: voxel exit (default) vs voxel centre\n\n" + table + "\n";
    }

    if (options.switches && scene->stages.Has(Stage::Shade)) {
        auto sw = MeasureSwitches(eval, scenePath, options, backends);
        if (!sw) {
            std::fprintf(stderr, "accuracy: switches: %s\n", sw.error().message.c_str());
            return kExitFailed;
        }
        std::printf("\nprincipal-axis switches: error on each side\n%s\njump at the switch\n%s",
                    sw->errorsTable.c_str(), sw->jumpTable.c_str());
        md += "## Principal-axis switches: error on each side\n\n" + sw->errorsTable + "\n## Jump at the switch\n\n" +
              sw->jumpTable + "\n";
        doc["switches"] = sw->doc;
    }

    doc["references"] = ReferencesJson(eval.Records(), options.cpuThreads);
    std::vector<std::vector<std::string>> speed;
    for (const ReferenceRecord& r : eval.Records())
        speed.push_back({r.key, std::to_string(r.primitives), Fmt("%.3f", r.buildSeconds),
                         std::to_string(r.tStats.rays), Fmt("%.3f", r.tStats.seconds),
                         Fmt("%.2f", r.tStats.RaysPerSecond() / 1e6), Fmt("%.2f", r.gStats.RaysPerSecond() / 1e6)});
    const std::string speedTable = Table(
        {"reference inputs", "boxes", "build s", "T_ref rays", "T_ref s", "T_ref M rays/s", "G_ref M rays/s"}, speed);
    std::printf("\nreference speed\n%s", speedTable.c_str());
    md += "## Reference speed\n\n" + speedTable;

    const std::string jsonPath = outDir + "/accuracy.json", mdPath = outDir + "/accuracy.md";
    Status a = WriteText(jsonPath, doc.dump(1) + "\n"), b = WriteText(mdPath, md);
    if (!a || !b) {
        std::fprintf(stderr, "%s\n", (!a ? a.error() : b.error()).message.c_str());
        return kExitFailed;
    }
    std::printf("results: %s %s\n", jsonPath.c_str(), mdPath.c_str());
    return kExitOk;
}

// ---- sweep -------------------------------------------------------------------------

namespace {

// Splits "V1,V2,..." at commas outside brackets, braces and quotes.
std::vector<std::string> SplitValues(const std::string& text) {
    std::vector<std::string> out;
    std::string current;
    int depth = 0;
    bool quoted = false;
    for (char ch : text) {
        if (ch == '"')
            quoted = !quoted;
        else if (!quoted && (ch == '[' || ch == '{'))
            ++depth;
        else if (!quoted && (ch == ']' || ch == '}'))
            --depth;
        if (ch == ',' && depth == 0 && !quoted) {
            out.push_back(current);
            current.clear();
        } else
            current += ch;
    }
    out.push_back(current);
    return out;
}

struct Axis {
    std::string path;
    std::vector<std::string> values;
};

// Pareto front per stage: no other ok row is at least as fast and as accurate
// and strictly better in one.
void MarkPareto(std::vector<Row>& rows, const std::string& metric) {
    auto error = [&](const Row& r) {
        return metric == "mean" ? r.result.all.mean : metric == "p99" ? r.result.all.p99 : r.result.all.max;
    };
    for (Row& r : rows) {
        if (r.result.status != "ok") continue;
        r.pareto = true;
        for (const Row& o : rows) {
            if (&o == &r || o.stage != r.stage || o.result.status != "ok") continue;
            const double t = o.result.timeMs.median, e = error(o);
            const double tr = r.result.timeMs.median, er = error(r);
            if (t <= tr && e <= er && (t < tr || e < er)) {
                r.pareto = false;
                break;
            }
        }
    }
}

}  // namespace

int SweepCommand(const CommonOptions& options) {
    if (options.vary.empty()) {
        std::fprintf(stderr, "sweep: needs at least one --vary PATH=V1,V2,...\n");
        return kExitUsage;
    }
    if (options.metric != "max" && options.metric != "mean" && options.metric != "p99") {
        std::fprintf(stderr, "sweep: --metric: must be max, mean or p99, got '%s'\n", options.metric.c_str());
        return kExitUsage;
    }
    std::vector<Axis> axes;
    for (const std::string& arg : options.vary) {
        const size_t eq = arg.find('=');
        if (eq == std::string::npos || eq == 0) {
            std::fprintf(stderr, "sweep: --vary '%s': expected PATH=V1,V2,... (a dotted scene path, '=', values)\n",
                         arg.c_str());
            return kExitUsage;
        }
        Axis axis{arg.substr(0, eq), SplitValues(arg.substr(eq + 1))};
        for (const std::string& v : axis.values)
            if (v.empty()) {
                std::fprintf(stderr, "sweep: --vary '%s': empty value in the list\n", arg.c_str());
                return kExitUsage;
            }
        for (const Axis& other : axes)
            if (other.path == axis.path) {
                std::fprintf(stderr, "sweep: --vary '%s': %s is varied twice\n", arg.c_str(), axis.path.c_str());
                return kExitUsage;
            }
        axes.push_back(std::move(axis));
    }
    const std::string scenePath = ResolveScenePath(options.scene);
    auto scene = LoadScene(scenePath, options.overrides);
    if (!scene) {
        std::fprintf(stderr, "%s\n", scene.error().message.c_str());
        return kExitBadScene;
    }
    // The cartesian product, every point validated before anything runs.
    std::vector<std::vector<SceneOverride>> points = {{}};
    for (const Axis& axis : axes) {
        std::vector<std::vector<SceneOverride>> next;
        for (const auto& p : points)
            for (const std::string& v : axis.values) {
                auto q = p;
                q.push_back({axis.path, v});
                next.push_back(std::move(q));
            }
        points = std::move(next);
    }
    for (const auto& point : points) {
        std::vector<SceneOverride> all = options.overrides;
        all.insert(all.end(), point.begin(), point.end());
        if (auto s = LoadScene(scenePath, all); !s) {
            std::fprintf(stderr, "sweep: --vary point %s:\n%s\n", SettingsLabel(point).c_str(),
                         s.error().message.c_str());
            return kExitBadScene;
        }
    }
    const std::string outDir = DefaultOut(options, *scene, "sweep");
    std::vector<BackendSlot> backends;
    if (std::optional<int> exitCode = OpenOutputAndBackends(options, outDir, backends)) return *exitCode;

    std::printf(
        "sweep of scene %s: %zu points x %zu backends, %d timed calls each, Pareto front on median time and "
        "%s error\n",
        scene->name.c_str(), points.size(), backends.size(), options.repeats, options.metric.c_str());
    Evaluator eval(options, ref::RayStart::VoxelExit);
    std::vector<Row> rows;
    // A stage is left out when every varied field belongs to the other one
    // (shadow's beer form reads shade.sigma, so that one counts for both).
    bool onlyShade = true, onlyShadow = true;
    for (const Axis& a : axes) {
        onlyShade &= a.path.starts_with("shade.") && a.path != "shade.sigma";
        onlyShadow &= a.path.starts_with("shadow.");
    }
    std::vector<Stage> stages;
    if (!onlyShadow) stages.push_back(Stage::Shade);
    if (!onlyShade) stages.push_back(Stage::Shadow);
    for (size_t n = 0; n < points.size(); ++n) {
        if (Status s = MeasureSetting(eval, scenePath, options, points[n], stages, backends, rows); !s) {
            std::fprintf(stderr, "sweep: %s: %s\n", SettingsLabel(points[n]).c_str(), s.error().message.c_str());
            return kExitFailed;
        }
        if (!options.quiet) std::fprintf(stderr, "sweep: point %zu/%zu done\n", n + 1, points.size());
    }
    MarkPareto(rows, options.metric);

    json doc = {{"format", "cloudbench-sweep/1"},
                {"scene", scene->name},
                {"grid", {scene->grid.size.nx, scene->grid.size.ny, scene->grid.size.nz}},
                {"step", scene->steps - 1},
                {"metric", options.metric},
                {"repeats", options.repeats},
                {"reference_start", "voxel-exit"},
                {"vary", json::array()},
                {"rows", json::array()}};
    for (const Axis& a : axes) doc["vary"].push_back({{"path", a.path}, {"values", a.values}});
    std::string md = "# Sweep of " + scene->name + "\n\nPareto front (*) on median time and " + options.metric +
                     " |error| over all elements, per stage.\n\n";
    for (Stage stage : stages) {
        std::vector<std::vector<std::string>> cells;
        for (const Row& r : rows) {
            if (r.stage != stage) continue;
            doc["rows"].push_back(RowJson(r));
            doc["rows"].back()["pareto"] = r.pareto;
            std::vector<std::string> c;
            for (const SceneOverride& o : r.settings) c.push_back(o.value);
            for (std::string& cell : RowCells(r, false)) c.push_back(std::move(cell));
            c.insert(c.begin() + ptrdiff_t(axes.size()) + 1, r.pareto ? "*" : "");
            cells.push_back(std::move(c));
        }
        if (cells.empty()) continue;
        std::vector<std::string> header;
        for (const Axis& a : axes) header.push_back(a.path);
        header.push_back("backend");
        header.push_back("pareto");
        std::vector<std::string> rest = Header({}, stage);
        header.insert(header.end(), rest.begin(), rest.end());
        const std::string table = Table(header, cells);
        std::printf("\n%s\n%s", std::string(StageName(stage)).c_str(), table.c_str());
        md += "## " + std::string(StageName(stage)) + "\n\n" + table + "\n";
    }
    doc["references"] = ReferencesJson(eval.Records(), options.cpuThreads);

    const std::string jsonPath = outDir + "/sweep.json", mdPath = outDir + "/sweep.md", pngPath = outDir + "/sweep.png";
    Status a = WriteText(jsonPath, doc.dump(1) + "\n"), b = WriteText(mdPath, md);
    if (!a || !b) {
        std::fprintf(stderr, "%s\n", (!a ? a.error() : b.error()).message.c_str());
        return kExitFailed;
    }
    // The plot: tools/plot_sweep.py (matplotlib). Without it the JSON and the table still stand.
    auto quote = [](const std::string& s) {
        std::string out = "'";
        for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
        return out + "'";
    };
    // Debian's python3-matplotlib is for /usr/bin/python3, which another python3
    // on the PATH (a virtual environment, pyenv) may hide: the first that has it.
    std::string python;
    for (const char* candidate : {"/usr/bin/python3", "python3"})
        if (std::system((std::string(candidate) + " -c 'import matplotlib' >/dev/null 2>&1").c_str()) == 0) {
            python = candidate;
            break;
        }
    const std::string script = std::string(CLOUDBENCH_TOOLS_DIR) + "/plot_sweep.py";
    const std::string command = python + " " + quote(script) + " " + quote(jsonPath) + " " + quote(pngPath);
    const bool plotted = !python.empty() && std::system(command.c_str()) == 0;
    if (python.empty())
        std::fprintf(stderr,
                     "sweep: no plot: python3 with matplotlib was not found (apt-get install "
                     "python3-matplotlib); %s and %s are written\n",
                     jsonPath.c_str(), mdPath.c_str());
    else if (!plotted)
        std::fprintf(stderr, "sweep: no plot: '%s' failed; %s and %s are written\n", command.c_str(), jsonPath.c_str(),
                     mdPath.c_str());
    std::printf("results: %s %s%s\n", jsonPath.c_str(), mdPath.c_str(), plotted ? (" " + pngPath).c_str() : "");
    return kExitOk;
}

// ---- dump --reference --------------------------------------------------------------

Status WriteReferenceDump(const Simulation& sim, const std::string& dir, int threads) {
    const Scene& scene = sim.GetScene();
    const bool wantT = scene.stages.Has(Stage::Shade), wantG = scene.stages.Has(Stage::Shadow);
    if ((!wantT && !wantG) || !sim.Q()) return {};
    LightingInputs in;
    in.grid = scene.grid.size;
    in.q.resize(in.grid.Count());
    CB_TRY(sim.GetBackend().Download(*sim.Q(), std::as_writable_bytes(std::span(in.q))));
    auto tracer = ref::OpticalDepthTracer::Create(in.grid, in.q, threads);
    if (!tracer) return std::unexpected(tracer.error());
    const ref::ReferenceParams p = MakeReferenceParams(scene, ref::RayStart::VoxelExit);
    const Extent3 e = in.grid;
    if (wantT) {
        const std::vector<float> T = (*tracer)->Transmittance(p);
        const uint64_t shape[3] = {e.nz, e.ny, e.nx};
        CB_TRY(WriteNpy(dir + "/T_ref.npy", NpyType::F32, shape, std::as_bytes(std::span(T))));
    }
    if (wantG) {
        const std::vector<float> G = (*tracer)->GroundShadow(p);
        const uint64_t shape[3] = {1, e.ny, e.nx};
        CB_TRY(WriteNpy(dir + "/shadow_ref.npy", NpyType::F32, shape, std::as_bytes(std::span(G))));
    }
    return {};
}

}  // namespace cb
