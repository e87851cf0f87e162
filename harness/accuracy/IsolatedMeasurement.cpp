#include "harness/accuracy/IsolatedMeasurement.h"

#include <cstdio>

#include "harness/accuracy/AccuracyTransfer.h"
#include "harness/accuracy/ImageAccuracy.h"
#include "harness/run/RunTransfer.h"

namespace cb {
using nlohmann::json;

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
        if (Describe(stage).renderer) {
            for (const OpenedBackend& slot : backends) {
                Row row{setting, slot.name, stage, {}, false, false};
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
            Row row{setting, slot.name, stage, {}, false, false};
            if (!slot.backend)
                row.result = NotMeasured("unavailable", slot.reason);
            else if (stage == Stage::Shade)
                row.result =
                    MeasureShade(*slot.backend, scene, *point->in, *point->reference, eval.Measurement().repeats);
            else
                row.result =
                    MeasureShadow(*slot.backend, scene, *point->in, *point->reference, eval.Measurement().repeats);
            if (row.result.status != "ok" && !options.quiet)
                std::fprintf(stderr, "%s %s %s: %s: %s\n", slot.name.c_str(), std::string(StageName(stage)).c_str(),
                             SettingsLabel(setting).c_str(), row.result.status.c_str(), row.result.detail.c_str());
            rows.push_back(std::move(row));
        }
    }
    return {};
}

namespace {

// In the child: opens the backend and measures the plan.
Result<json> MeasureHere(Session& session, const MeasurementOptions& measurement, const std::string& name,
                         const std::vector<PlannedSetting>& plan, const MoreMeasurements& more,
                         const std::function<void(size_t)>& progress) {
    MarkPhase("opening backend");
    const std::vector<OpenedBackend> backends = session.OpenBackends({name});
    json out = {{"provenance", transfer::ToJson(session.BackendRecords().back())},
                {"available", backends[0].backend != nullptr}};
    if (!backends[0].backend) return out;
    Evaluator eval(session, measurement, ref::RayStart::VoxelExit);
    out["rows"] = json::array();
    for (size_t k = 0; k < plan.size(); ++k) {
        MarkPhase("measuring " + SettingsLabel(plan[k].setting));
        std::vector<Row> rows;
        if (Status s = MeasureSetting(eval, plan[k].setting, plan[k].stages, backends, rows); !s)
            return MakeError(SettingsLabel(plan[k].setting) + ": " + s.error().message);
        json list = json::array();
        for (const Row& row : rows) list.push_back(transfer::ToJson(row));
        out["rows"].push_back(list);
        if (progress) progress(k);
    }
    if (more) {
        auto extra = more(eval, backends);
        if (!extra) return std::unexpected(extra.error());
        out["extra"] = std::move(*extra);
    }
    out["records"] = json::array();
    for (const ReferenceRecord& r : eval.Records()) out["records"].push_back(transfer::ToJson(r));
    MarkPhase("closing backend");
    return out;
}

}  // namespace

Result<std::vector<BackendMeasurement>> MeasureEachBackend(Session& session, const MeasurementOptions& measurement,
                                                           const std::vector<std::string>& names,
                                                           const std::vector<PlannedSetting>& plan,
                                                           const MoreMeasurements& more,
                                                           const std::function<void(size_t)>& progress) {
    std::vector<BackendMeasurement> parts;
    for (const std::string& name : names) {
        BackendMeasurement part;
        part.name = name;
        IsolatedOutcome outcome =
            RunIsolated("backend " + name, IsolationFrom(session.Options()), [&](const SendMessage&) -> json {
                auto measured = MeasureHere(session, measurement, name, plan, more, progress);
                if (!measured) return {{"error", measured.error().message}};
                return *measured;
            });
        if (!outcome.result) {
            part.failure = outcome.failure;
            part.available = true;  // asked for and not finished: a failure, not "no backend"
            std::fprintf(stderr, "backend %s %s\n", name.c_str(), part.failure->Describe().c_str());
            session.AddBackendRecord({name, part.failure->stage == "opening backend" ? "unavailable" : "available", "",
                                      part.failure->Describe()});
            parts.push_back(std::move(part));
            continue;
        }
        const json& r = *outcome.result;
        if (r.contains("error")) return MakeError(r["error"].get<std::string>());
        const BackendProvenance record = transfer::ProvenanceFromJson(r["provenance"]);
        session.AddBackendRecord(record);
        part.status = record.status;
        part.reason = record.reason;
        part.available = r["available"].get<bool>();
        if (r.contains("rows"))
            for (const json& item : r["rows"]) {
                part.rows.emplace_back();
                for (const json& row : item) part.rows.back().push_back(transfer::RowFromJson(row));
            }
        if (r.contains("records"))
            for (const json& record : r["records"]) part.records.push_back(transfer::ReferenceRecordFromJson(record));
        if (r.contains("extra")) part.extra = r["extra"];
        parts.push_back(std::move(part));
    }
    return parts;
}

std::vector<Row> MergeRows(const Scene& scene, const std::vector<PlannedSetting>& plan,
                           const std::vector<BackendMeasurement>& parts, std::vector<size_t>* itemOf) {
    std::vector<Row> rows;
    for (size_t k = 0; k < plan.size(); ++k) {
        for (const BackendMeasurement& part : parts) {
            if (k < part.rows.size()) {
                rows.insert(rows.end(), part.rows[k].begin(), part.rows[k].end());
                continue;
            }
            // Not measured: the backend did not open, or its process died.
            for (Stage stage : plan[k].stages) {
                if (!scene.stages.Has(stage)) continue;
                Row row{plan[k].setting, part.name, stage, {}, false, false};
                if (part.failure)
                    row.result = NotMeasured(part.failure->status, part.failure->Describe());
                else
                    row.result = NotMeasured(part.status, part.reason);
                rows.push_back(std::move(row));
            }
        }
        if (itemOf) itemOf->resize(rows.size(), k);
    }
    return rows;
}

std::vector<ReferenceRecord> FirstRecords(const std::vector<BackendMeasurement>& parts) {
    for (const BackendMeasurement& part : parts)
        if (!part.records.empty()) return part.records;
    return {};
}

}  // namespace cb
