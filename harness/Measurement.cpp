#include "harness/Measurement.h"

#include <cstdio>

#include "harness/ImageAccuracy.h"

namespace cb {
using nlohmann::json;

namespace {

bool IsRenderer(Stage s) { return s == Stage::RenderMarch || s == Stage::RenderSplat; }

// Paths whose value changes only the lighting stages, not q or D.
bool LightingOnly(const std::string& path) {
    for (const char* prefix :
         {"shade", "shadow", "sun", "phase", "render", "lighting", "description", "march", "lightning"})
        if (path == prefix || path.starts_with(std::string(prefix) + ".")) return true;
    return false;
}

}  // namespace

json TimeJson(const Summary& s) {
    return {{"median_ms", s.median}, {"q1_ms", s.q1},   {"q3_ms", s.q3},
            {"min_ms", s.min},       {"max_ms", s.max}, {"count", s.count}};
}

std::string Fmt(const char* format, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, format, value);
    return buffer;
}

Result<const LightingInputs*> Evaluator::Inputs(const Scene& scene, const std::vector<SceneOverride>& overrides) {
    std::string key;
    for (const SceneOverride& o : overrides)
        if (!LightingOnly(o.path)) key += o.path + "=" + o.value + ";";
    auto it = mInputs.find(key);
    if (it == mInputs.end()) {
        if (!mSession.Options().quiet)
            std::fprintf(stderr, "simulating %u steps of %s%s%s\n", scene.steps, scene.name.c_str(),
                         key.empty() ? "" : " with ", key.c_str());
        auto in = SimulateLightingInputs(scene, mSession.Options().cpuThreads);
        if (!in) return std::unexpected(in.error());
        KeepOnlyLast(mInputs, mLastKey);
        it = mInputs.emplace(key, std::move(*in)).first;
    }
    mLastKey = key;
    return &it->second;
}

Result<const ReferenceResult*> Evaluator::Reference(const Scene& scene, const LightingInputs& in, ref::RayStart start) {
    const Vec3 s = scene.sun.Direction();
    const std::string key = mLastKey + "|sun " + Fmt("%.9g", s[0]) + " " + Fmt("%.9g", s[1]) + " " + Fmt("%.9g", s[2]) +
                            " sigma " + Fmt("%.17g", scene.shade.sigma) + " h " + Fmt("%.17g", scene.grid.voxelSize) +
                            " " + ref::RayStartName(start);
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
        auto r = ComputeReference(scene, in, start, mSession.Options().cpuThreads);
        if (!r) return std::unexpected(r.error());
        ReferenceRecord rec{label, r->tStats, r->gStats, r->buildSeconds, r->primitives};
        if (!mSession.Options().quiet)
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
ImageReferences& Evaluator::Images() {
    if (!mImages) mImages = std::make_shared<ImageReferences>(*this, mSession);
    return *mImages;
}

Result<Evaluator::Point> Evaluator::Load(std::span<const SceneOverride> extra) {
    auto scene = mSession.LoadVariant(extra);
    if (!scene) return std::unexpected(scene.error());
    std::vector<SceneOverride> all = mSession.Options().overrides;
    all.insert(all.end(), extra.begin(), extra.end());
    auto in = Inputs(*scene, all);
    if (!in) return std::unexpected(in.error());
    auto reference = Reference(*scene, **in);
    if (!reference) return std::unexpected(reference.error());
    return Point{std::move(*scene), *in, *reference};
}

json StatsJson(const ErrorStats& e) {
    return {{"count", e.count}, {"max", e.max}, {"mean", e.mean}, {"p99", e.p99}, {"worst_index", e.worst}};
}

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
        if (IsRenderer(r.stage))
            j["error"] = {{"all", StatsJson(r.result.all)},
                          {"psnr_db", r.result.psnrDb ? json(*r.result.psnrDb) : json(nullptr)}};
        else
            j["error"] = {{"all", StatsJson(r.result.all)},
                          {r.stage == Stage::Shade ? "in_cloud" : "under_cloud", StatsJson(r.result.subset)}};
    }
    return j;
}

Status MeasureSetting(Evaluator& eval, const std::vector<SceneOverride>& setting, std::span<const Stage> stages,
                      std::span<const OpenedBackend> backends, std::vector<Row>& rows) {
    const bool lighting = std::ranges::any_of(stages, [](Stage s) { return s == Stage::Shade || s == Stage::Shadow; });
    std::optional<Evaluator::Point> point;
    if (lighting) {
        auto loaded = eval.Load(setting);
        if (!loaded) return std::unexpected(loaded.error());
        point = std::move(*loaded);
    } else {
        auto scene = eval.GetSession().LoadVariant(setting);
        if (!scene) return std::unexpected(scene.error());
        point = Evaluator::Point{std::move(*scene), nullptr, nullptr};
    }
    const Scene& scene = point->scene;
    const CommonOptions& options = eval.Options();
    for (Stage stage : stages) {
        if (!scene.stages.Has(stage)) continue;
        if (stage == Stage::RenderMarch || stage == Stage::RenderSplat) {
            for (const OpenedBackend& slot : backends) {
                Row row{setting, slot.name, stage, {}, false};
                if (!slot.backend)
                    row.result = NotMeasured("unavailable", slot.reason);
                else {
                    auto a = MeasureImageStage(eval, setting, stage, *slot.backend);
                    if (!a) return std::unexpected(a.error());
                    row.result = std::move(*a);
                }
                if (row.result.status != "ok" && !options.quiet)
                    std::fprintf(stderr, "%s %s %s: %s: %s\n", slot.name.c_str(), std::string(StageName(stage)).c_str(),
                                 SettingsLabel(setting).c_str(), row.result.status.c_str(), row.result.detail.c_str());
                rows.push_back(std::move(row));
            }
            continue;
        }
        for (const OpenedBackend& slot : backends) {
            Row row{setting, slot.name, stage, {}, false};
            if (!slot.backend)
                row.result = NotMeasured("unavailable", slot.reason);
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

std::vector<report::Column> StatsColumns(const std::string& suffix) {
    std::vector<report::Column> columns;
    for (const char* title : {"max", "mean", "p99"}) columns.push_back(report::Column(title + suffix).Real("%.3g"));
    return columns;
}

std::vector<report::Cell> StatsCells(const ErrorStats& e) { return {e.max, e.mean, e.p99}; }

std::vector<report::Column> ErrorColumns(std::initializer_list<std::string> first, Stage stage) {
    std::vector<report::Column> columns;
    for (const std::string& title : first) columns.emplace_back(title);
    columns.emplace_back("backend");
    columns.push_back(report::Column("time ms (q1-q3)").Unit("ms"));
    for (auto& c : StatsColumns()) columns.push_back(c);
    if (IsRenderer(stage)) {
        columns.push_back(report::Column("PSNR dB").Real("%.2f"));
        return columns;
    }
    for (auto& c : StatsColumns(stage == Stage::Shade ? " (in cloud)" : " (under cloud)")) columns.push_back(c);
    return columns;
}

std::vector<report::Cell> RowCells(const Row& r) {
    std::vector<report::Cell> cells = {r.backend};
    if (r.result.status != "ok") {
        cells.push_back(r.result.status + ": " + r.result.detail);
        return cells;
    }
    const Summary& t = r.result.timeMs;
    cells.push_back(Fmt("%.3f", t.median) + " (" + Fmt("%.3f", t.q1) + "-" + Fmt("%.3f", t.q3) + ")");
    for (auto& c : StatsCells(r.result.all)) cells.push_back(c);
    if (IsRenderer(r.stage)) {
        cells.push_back(r.result.psnrDb ? report::Cell(*r.result.psnrDb) : report::Cell("inf"));
        return cells;
    }
    for (auto& c : StatsCells(r.result.subset)) cells.push_back(c);
    return cells;
}

report::Table ReferenceSpeedTable(const std::vector<ReferenceRecord>& records) {
    using report::Column;
    report::Table table({Column("reference inputs"), Column("boxes").Integer(),
                         Column("build s").Real("%.3f").Unit("s"), Column("T_ref rays").Integer(),
                         Column("T_ref s").Real("%.3f").Unit("s"), Column("T_ref M rays/s").Real("%.2f"),
                         Column("G_ref M rays/s").Real("%.2f")});
    for (const ReferenceRecord& r : records)
        table.rows.push_back({r.key, int64_t(r.primitives), r.buildSeconds, int64_t(r.tStats.rays), r.tStats.seconds,
                              r.tStats.RaysPerSecond() / 1e6, r.gStats.RaysPerSecond() / 1e6});
    return table;
}

report::Table TextTable(std::initializer_list<std::string> titles) {
    report::Table table;
    for (const std::string& title : titles) table.columns.emplace_back(title);
    return table;
}

}  // namespace cb
