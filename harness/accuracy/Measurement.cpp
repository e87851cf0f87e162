#include "harness/accuracy/Measurement.h"

#include <cstdio>

namespace cb {
using nlohmann::json;

namespace {

bool IsRenderer(Stage s) { return Describe(s).renderer; }

}  // namespace

json TimeJson(const Summary& s) {
    return {{"median_ms", s.median}, {"q1_ms", s.q1},   {"q3_ms", s.q3},
            {"min_ms", s.min},       {"max_ms", s.max}, {"count", s.count}};
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

std::vector<report::Column> StatsColumns(const std::string& suffix) {
    std::vector<report::Column> columns;
    for (const char* title : {"max", "mean", "p99"})
        columns.push_back(report::Column(title + suffix).Real(kErrorFormat));
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
        columns.push_back(report::Column("PSNR dB").Real(kPsnrFormat));
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
