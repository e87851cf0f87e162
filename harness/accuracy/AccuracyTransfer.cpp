#include "harness/accuracy/AccuracyTransfer.h"

#include "harness/platform/TransferJson.h"
#include "harness/report/ReportTransfer.h"

namespace cb::transfer {

json ToJson(const ErrorStats& e) {
    return {{"count", e.count}, {"max", D(e.max)}, {"mean", D(e.mean)}, {"p99", D(e.p99)}, {"worst", e.worst}};
}
ErrorStats ErrorStatsFromJson(const json& j) {
    return {j.at("count").get<uint64_t>(), FromD(j.at("max")), FromD(j.at("mean")), FromD(j.at("p99")),
            j.at("worst").get<uint64_t>()};
}

json ToJson(const Row& r) {
    json settings = json::array();
    for (const SceneOverride& o : r.settings) settings.push_back({o.path, o.value});
    return {{"settings", settings},        {"backend", r.backend},
            {"stage", StageName(r.stage)}, {"status", r.result.status},
            {"detail", r.result.detail},   {"time", ToJson(r.result.timeMs)},
            {"all", ToJson(r.result.all)}, {"subset", ToJson(r.result.subset)},
            {"pareto", r.pareto},          {"psnr_db", r.result.psnrDb ? json(*r.result.psnrDb) : json(nullptr)}};
}
Row RowFromJson(const json& j) {
    Row r;
    for (const json& o : j.at("settings"))
        r.settings.push_back({o.at(0).get<std::string>(), o.at(1).get<std::string>()});
    r.backend = j.at("backend").get<std::string>();
    r.stage = ParseStage(j.at("stage").get<std::string>()).value_or(Stage::Shade);
    r.result.status = j.at("status").get<std::string>();
    r.result.detail = j.at("detail").get<std::string>();
    r.result.timeMs = SummaryFromJson(j.at("time"));
    r.result.all = ErrorStatsFromJson(j.at("all"));
    r.result.subset = ErrorStatsFromJson(j.at("subset"));
    r.pareto = j.at("pareto").get<bool>();
    if (j.contains("psnr_db") && !j["psnr_db"].is_null()) r.result.psnrDb = j["psnr_db"].get<double>();
    return r;
}

json ToJson(const ReferenceRecord& r) {
    return {{"key", r.key},
            {"t_rays", r.tStats.rays},
            {"t_seconds", D(r.tStats.seconds)},
            {"g_rays", r.gStats.rays},
            {"g_seconds", D(r.gStats.seconds)},
            {"build_seconds", D(r.buildSeconds)},
            {"primitives", r.primitives}};
}
ReferenceRecord ReferenceRecordFromJson(const json& j) {
    ReferenceRecord r;
    r.key = j.at("key").get<std::string>();
    r.tStats = {j.at("t_rays").get<uint64_t>(), FromD(j.at("t_seconds"))};
    r.gStats = {j.at("g_rays").get<uint64_t>(), FromD(j.at("g_seconds"))};
    r.buildSeconds = FromD(j.at("build_seconds"));
    r.primitives = j.at("primitives").get<size_t>();
    return r;
}

}  // namespace cb::transfer
