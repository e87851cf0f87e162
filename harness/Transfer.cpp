#include "harness/Transfer.h"

#include <cmath>
#include <limits>

namespace cb::transfer {
using nlohmann::json;

namespace {

// A double, non-finite values included (JSON numbers cannot hold them).
json D(double v) {
    if (std::isfinite(v)) return v;
    return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
}
double FromD(const json& j) {
    if (j.is_number()) return j.get<double>();
    const std::string text = j.get<std::string>();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
    return text == "inf" ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
}

json Optional(const std::optional<double>& value) { return value ? D(*value) : json(nullptr); }
json Optional(const std::optional<uint32_t>& value) { return value ? json(*value) : json(nullptr); }
template <typename T>
std::optional<T> OptionalFrom(const json& j) {
    if (j.is_null()) return std::nullopt;
    if constexpr (std::is_same_v<T, double>)
        return FromD(j);
    else
        return j.get<T>();
}

json ToJson(const Summary& s) {
    return {{"count", s.count}, {"median", D(s.median)}, {"q1", D(s.q1)},
            {"q3", D(s.q3)},    {"min", D(s.min)},       {"max", D(s.max)}};
}
Summary SummaryFromJson(const json& j) {
    return {j.at("count").get<size_t>(), FromD(j.at("median")), FromD(j.at("q1")),
            FromD(j.at("q3")),           FromD(j.at("min")),    FromD(j.at("max"))};
}

json ToJson(const ErrorStats& e) {
    return {{"count", e.count}, {"max", D(e.max)}, {"mean", D(e.mean)}, {"p99", D(e.p99)}, {"worst", e.worst}};
}
ErrorStats ErrorStatsFromJson(const json& j) {
    return {j.at("count").get<uint64_t>(), FromD(j.at("max")), FromD(j.at("mean")), FromD(j.at("p99")),
            j.at("worst").get<uint64_t>()};
}

}  // namespace

json ToJson(const StepRecord& r) {
    json stageMs = json::array(), hostMs = json::array(), deviceMs = json::array(), frames = json::array(),
         skipped = json::array();
    for (size_t s = 0; s < kStageCount; ++s) {
        stageMs.push_back(Optional(r.stageMs[s]));
        hostMs.push_back(Optional(r.hostMs[s]));
        deviceMs.push_back(Optional(r.deviceMs[s]));
        skipped.push_back(r.skippedUnchanged[s]);
    }
    for (const FrameRecord& f : r.frames)
        frames.push_back({{"renderer", StageName(f.renderer)},
                          {"camera", f.camera},
                          {"frame", f.frame},
                          {"alpha", D(f.alpha)},
                          {"ms", D(f.ms)},
                          {"pipelined", f.pipelined},
                          {"device_ms", Optional(f.deviceMs)},
                          {"splats", f.stats.splats},
                          {"voxels_visited", f.stats.voxelsVisited},
                          {"fragments", f.stats.fragments},
                          {"march",
                           {{"rays", f.march.rays},
                            {"samples", f.march.samples},
                            {"light_samples", f.march.lightSamples},
                            {"bricks_skipped", f.march.bricksSkipped},
                            {"empty_bricks", f.march.emptyBricks},
                            {"bricks", f.march.bricks}}}});
    json frameMs = json::array();
    for (double ms : r.frameMs) frameMs.push_back(D(ms));
    return {{"step", r.step},
            {"timing", TimingModeName(r.timing)},
            {"stage_ms", stageMs},
            {"host_ms", hostMs},
            {"submissions", r.submissions},
            {"host_waits", r.hostWaits},
            {"batches", r.batches},
            {"device_ms", deviceMs},
            {"ellipsoid_update_ms", D(r.ellipsoidUpdateMs)},
            {"covered_columns", Optional(r.coveredColumns)},
            {"skipped_unchanged", skipped},
            {"frames_rendered", r.framesRendered},
            {"step_ms", D(r.stepMs)},
            {"frame_ms", frameMs},
            {"frame_work", r.frameWork},
            {"frames", frames}};
}

StepRecord StepFromJson(const json& j) {
    StepRecord r;
    r.step = j.at("step").get<uint32_t>();
    for (size_t s = 0; s < kStageCount; ++s) {
        r.stageMs[s] = OptionalFrom<double>(j.at("stage_ms").at(s));
        r.deviceMs[s] = OptionalFrom<double>(j.at("device_ms").at(s));
        r.hostMs[s] = OptionalFrom<double>(j.at("host_ms").at(s));
    }
    r.timing = j.at("timing").get<std::string>() == "pipelined" ? TimingMode::Pipelined : TimingMode::Synchronized;
    r.submissions = j.at("submissions").get<uint64_t>();
    r.hostWaits = j.at("host_waits").get<uint64_t>();
    r.batches = j.at("batches").get<uint32_t>();
    r.ellipsoidUpdateMs = FromD(j.at("ellipsoid_update_ms"));
    r.coveredColumns = OptionalFrom<uint32_t>(j.at("covered_columns"));
    for (size_t s = 0; s < kStageCount; ++s) r.skippedUnchanged[s] = j.at("skipped_unchanged").at(s).get<bool>();
    r.framesRendered = j.at("frames_rendered").get<uint32_t>();
    r.stepMs = FromD(j.at("step_ms"));
    for (const json& ms : j.at("frame_ms")) r.frameMs.push_back(FromD(ms));
    r.frameWork = j.at("frame_work").get<std::vector<std::string>>();
    for (const json& f : j.at("frames")) {
        FrameRecord frame;
        frame.renderer = ParseStage(f.at("renderer").get<std::string>()).value_or(Stage::RenderSplat);
        frame.camera = f.at("camera").get<std::string>();
        frame.frame = f.at("frame").get<uint32_t>();
        frame.alpha = float(FromD(f.at("alpha")));
        frame.ms = FromD(f.at("ms"));
        frame.pipelined = f.at("pipelined").get<bool>();
        frame.deviceMs = OptionalFrom<double>(f.at("device_ms"));
        frame.stats = {f.at("splats").get<uint64_t>(), f.at("voxels_visited").get<uint64_t>(),
                       f.at("fragments").get<uint64_t>()};
        if (const auto m = f.find("march"); m != f.end())
            frame.march = {m->at("rays").get<uint64_t>(),          m->at("samples").get<uint64_t>(),
                           m->at("light_samples").get<uint64_t>(), m->at("bricks_skipped").get<uint64_t>(),
                           m->at("empty_bricks").get<uint64_t>(),  m->at("bricks").get<uint64_t>()};
        r.frames.push_back(std::move(frame));
    }
    return r;
}

json ToJson(const BackendProvenance& b) {
    return {{"name", b.name}, {"status", b.status}, {"device", b.device}, {"reason", b.reason}};
}
BackendProvenance ProvenanceFromJson(const json& j) {
    return {j.at("name").get<std::string>(), j.at("status").get<std::string>(), j.at("device").get<std::string>(),
            j.at("reason").get<std::string>()};
}

json ToJson(const ConformRow& r) {
    return {{"stage", r.stage},    {"backend", r.backend},
            {"status", r.status},  {"rule", r.rule},
            {"worst", D(r.worst)}, {"tolerance", D(r.tolerance)},
            {"detail", r.detail},  {"difference_image", r.differenceImage}};
}
ConformRow ConformRowFromJson(const json& j) {
    ConformRow r;
    r.stage = j.at("stage").get<std::string>();
    r.backend = j.at("backend").get<std::string>();
    r.status = j.at("status").get<std::string>();
    r.rule = j.at("rule").get<std::string>();
    r.worst = FromD(j.at("worst"));
    r.tolerance = FromD(j.at("tolerance"));
    r.detail = j.at("detail").get<std::string>();
    r.differenceImage = j.value("difference_image", "");
    return r;
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

json ToJson(const std::vector<report::Cell>& cells) {
    json out = json::array();
    for (const report::Cell& c : cells) switch (c.kind) {
            case report::Cell::Kind::Empty:
                out.push_back(nullptr);
                break;
            case report::Cell::Kind::Text:
                out.push_back({{"text", c.text}});
                break;
            case report::Cell::Kind::Real:
                out.push_back({{"real", D(c.real)}});
                break;
            case report::Cell::Kind::Integer:
                out.push_back({{"integer", c.integer}});
                break;
        }
    return out;
}
std::vector<report::Cell> CellsFromJson(const json& j) {
    std::vector<report::Cell> cells;
    for (const json& c : j) {
        if (c.is_null())
            cells.emplace_back();
        else if (c.contains("text"))
            cells.emplace_back(c["text"].get<std::string>());
        else if (c.contains("real"))
            cells.emplace_back(FromD(c["real"]));
        else
            cells.emplace_back(c.at("integer").get<int64_t>());
    }
    return cells;
}

}  // namespace cb::transfer
