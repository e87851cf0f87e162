// `cloudbench merge`: the sweep.json files of `sweep --shard I/N` into one
// sweep (the table the unsharded sweep writes), or perf histories from several
// machines into one history.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "core/base/ShownText.h"
#include "harness/accuracy/AccuracyTransfer.h"
#include "harness/accuracy/Measurement.h"
#include "harness/commands/SweepOutput.h"
#include "harness/perf/History.h"
#include "harness/platform/Command.h"
#include "harness/report/InputFormats.h"
#include "harness/run/Session.h"
#include "harness/run/VaryAxes.h"

namespace cb {
namespace {

using nlohmann::json;

constexpr const char* kHelp = R"(usage: cloudbench merge FILE... --out DIR

Combines, when every FILE is the sweep.json of one `sweep --shard I/N` (same
scene, grid, step, vary, metric, repeats and N; each index 1..N exactly once),
their rows into DIR/sweep.json, sweep.md and sweep.png: the rows in the order
the unsharded sweep gives them (stage, point, backend), the Pareto front
recomputed over all rows, the references of every shard.

Combines, when every FILE is a perf history (JSON Lines of cloudbench-perf/1
records, e.g. from several machines), their records into DIR/history.jsonl:
each record once (by "id"; the first one read is kept), ordered by "time" and
then "id". A line that is not a record is skipped with a warning.

  --out DIR   the folder to write (created when missing; required)

Exits 0 when written, 1 when an output cannot be written, 2 for a bad command
line (no file, no --out, sweeps and histories mixed), 3 for a file that cannot
be read or a set of shards that does not fit together (the message names the
file and the field).
)";

enum class InputKind { Sweep, History };

struct Input {
    std::string path;
    InputKind kind = InputKind::History;
    json sweep;                                // InputKind::Sweep: the document
    std::vector<perf::HistoryRecord> records;  // InputKind::History
};

// A sweep.json (one JSON object of format cloudbench-sweep/1) or a history
// (JSON Lines of cloudbench-perf/1 records); an error message otherwise.
Result<Input> ReadInput(const std::string& path) {
    static constexpr input::Format kSweep[] = {input::Format::Sweep};
    auto read = input::ReadDocumentOrHistory(path, kSweep);
    if (!read) return std::unexpected(read.error());
    Input in;
    in.path = path;
    if (auto* sweep = std::get_if<input::Document>(&*read)) {
        in.kind = InputKind::Sweep;
        in.sweep = std::move(sweep->doc);
        return in;
    }
    input::History& history = std::get<input::History>(*read);
    input::PrintWarnings(history);
    in.records = std::move(history.records);
    return in;
}

int Fail(const std::string& message, int code) {
    std::fprintf(stderr, "merge: %s\n", message.c_str());
    return code;
}

int MergeSweeps(const std::vector<Input>& inputs, const std::string& outDir) {
    // The fields every shard must share with the first, and the shard block's shape.
    const json& first = inputs.front().sweep;
    const std::vector<std::string> shared = {"scene", "grid", "step", "vary", "metric", "repeats"};
    std::map<int, const Input*> byIndex;
    int count = 0;
    size_t points = 0;
    try {
        for (const Input& input : inputs) {
            const json& doc = input.sweep;
            if (!doc.contains("shard") || !doc["shard"].is_object())
                return Fail(input.path + ": /shard: missing (not the output of sweep --shard I/N)", kExitBadScene);
            for (const std::string& field : shared)
                if (!doc.contains(field) || doc[field] != first.value(field, json()))
                    return Fail(input.path + ": /" + field + ": differs from " + inputs.front().path, kExitBadScene);
            const json& shard = doc["shard"];
            const int index = shard.at("index").get<int>();
            if (&input == &inputs.front()) {
                count = shard.at("count").get<int>();
                points = shard.at("points").get<size_t>();
            }
            if (shard.at("count").get<int>() != count)
                return Fail(input.path + ": /shard/count: differs from " + inputs.front().path, kExitBadScene);
            if (shard.at("points").get<size_t>() != points)
                return Fail(input.path + ": /shard/points: differs from " + inputs.front().path, kExitBadScene);
            if (index < 1 || index > count)
                return Fail(
                    input.path + ": /shard/index: " + std::to_string(index) + " is not in 1.." + std::to_string(count),
                    kExitBadScene);
            if (auto [it, fresh] = byIndex.emplace(index, &input); !fresh)
                return Fail(input.path + ": /shard/index: " + std::to_string(index) + " also in " + it->second->path,
                            kExitBadScene);
        }
        for (int i = 1; i <= count; ++i)
            if (!byIndex.contains(i))
                return Fail(inputs.front().path + ": /shard/index: shard " + std::to_string(i) + " of " +
                                std::to_string(count) + " is missing",
                            kExitBadScene);

        // Every row's point must be one of its shard's (k % N == I-1, k below the point count) and hold that
        // point's settings: a wrong index would put a row in another point's place.
        std::vector<SweepAxis> axes;
        for (const json& a : first.at("vary"))
            axes.push_back({a.at("path").get<std::string>(), a.at("values").get<std::vector<std::string>>()});
        const uint64_t product = VaryPointCount(axes);
        if (product != points)
            return Fail(inputs.front().path + ": /shard/points: " + std::to_string(points) + ", but its /vary axes make " +
                            std::to_string(product) + " points",
                        kExitBadScene);
        if (product > kMaxVaryPoints)
            return Fail(inputs.front().path + ": /vary: " + std::to_string(product) + " points, more than the " +
                            std::to_string(kMaxVaryPoints) + " a sweep may have",
                        kExitBadScene);
        const std::vector<std::vector<SceneOverride>> pointSettings = VaryPoints(axes);
        for (const auto& [index, input] : byIndex) {
            const json& rows = input->sweep["shard"]["rows"];
            for (size_t r = 0; r < rows.size(); ++r) {
                const std::string field = input->path + ": /shard/rows/" + std::to_string(r);
                const size_t point = rows[r]["point"].get<size_t>();
                if (point >= points || int(point % size_t(count)) != index - 1)
                    return Fail(field + "/point: " + std::to_string(point) + " is not a point of shard " +
                                    std::to_string(index) + "/" + std::to_string(count) + " (k % " +
                                    std::to_string(count) + " == " + std::to_string(index - 1) + ", k < " +
                                    std::to_string(points) + ")",
                                kExitBadScene);
                const json& settings = rows[r]["settings"];
                bool same = settings.size() == pointSettings[point].size();
                for (size_t k = 0; same && k < settings.size(); ++k)
                    same = settings[k][0] == pointSettings[point][k].path && settings[k][1] == pointSettings[point][k].value;
                if (!same)
                    return Fail(field + "/settings: " + ShownText(settings.dump(), false, 120) + " are not point " + std::to_string(point) +
                                    "'s settings (" + SettingsLabel(pointSettings[point]) + ")",
                                kExitBadScene);
            }
        }

        // Each point is in one shard, so ordering the shards' rows by point
        // (stably: a shard keeps its backend order within a point) gives the
        // unsharded order; WriteSweepOutputs then groups them by stage.
        struct PointRow {
            size_t point;
            Row row;
        };
        std::vector<PointRow> all;
        json references = json::array();
        json provenances = json::array();
        for (const auto& [index, input] : byIndex) {
            for (const json& r : input->sweep["shard"].at("rows"))
                all.push_back({r.at("point").get<size_t>(), transfer::RowFromJson(r)});
            for (const json& ref : input->sweep.value("references", json::array())) references.push_back(ref);
            provenances.push_back(input->sweep.value("provenance", json()));
        }
        std::ranges::stable_sort(all, {}, &PointRow::point);
        std::vector<Row> rows;
        for (PointRow& p : all) {
            p.row.pareto = false;
            rows.push_back(std::move(p.row));
        }
        const std::string metric = first.at("metric").get<std::string>();
        MarkPareto(rows, metric);

        json doc = {{"format", "cloudbench-sweep/1"}, {"references", references}};
        for (const char* field : {"scene", "grid", "step", "metric", "repeats", "reference_start"})
            if (first.contains(field)) doc[field] = first[field];
        std::printf("merge: %d shards of %zu points, %zu rows\n", count, points, rows.size());
        // The provenance of shard 1 (the shape readers expect), with every shard's under "shards".
        return WriteSweepOutputs(std::move(doc), first.at("scene").get<std::string>(), metric, axes, SweepStages(axes),
                                 rows, outDir, [&](const std::string& path, json d) {
                                     d["provenance"] = provenances.at(0);
                                     d["provenance"]["shards"] = provenances;
                                     return Session::WriteText(path, d.dump(1) + "\n");
                                 });
    } catch (const json::exception& e) {
        return Fail(std::string("a shard file has an unexpected shape: ") + e.what(), kExitBadScene);
    }
}

int MergeHistories(const std::vector<Input>& inputs, const std::string& outDir) {
    std::vector<json> records;
    std::set<std::string> seen;
    size_t duplicates = 0;
    for (const Input& input : inputs)
        for (const perf::HistoryRecord& r : input.records) {
            const std::string id =
                r.record.contains("id") && r.record["id"].is_string() ? r.record["id"].get<std::string>() : "";
            if (id.empty()) {
                std::fprintf(stderr, "warning: %s:%zu: a record without an id, skipped\n", input.path.c_str(), r.line);
                continue;
            }
            if (!seen.insert(id).second) {
                ++duplicates;
                continue;
            }
            records.push_back(r.record);
        }
    // A record's "time" (ISO 8601 UTC text, so text order is time order) and "id"; a missing or non-text field sorts as
    // "".
    auto textField = [](const json& r, const char* field) {
        return r.contains(field) && r[field].is_string() ? r[field].get<std::string>() : std::string();
    };
    auto key = [&](const json& r) { return std::pair(textField(r, "time"), textField(r, "id")); };
    std::ranges::stable_sort(records, [&](const json& a, const json& b) { return key(a) < key(b); });
    std::string text;
    for (const json& r : records) text += r.dump() + "\n";
    const std::string path = outDir + "/history.jsonl";
    if (Status s = Session::WriteText(path, text); !s) return Fail(s.error().message, kExitFailed);
    std::printf("merge: %zu records (%zu duplicates dropped) -> %s\n", records.size(), duplicates, path.c_str());
    return kExitOk;
}

int Merge(const CommonOptions& options) {
    if (options.arguments.empty()) return Fail("needs sweep.json files of sweep --shard, or histories", kExitUsage);
    if (options.outDir.empty()) return Fail("needs --out DIR", kExitUsage);
    std::vector<Input> inputs;
    for (const std::string& path : options.arguments) {
        auto input = ReadInput(path);
        if (!input) return Fail(input.error().message, kExitBadScene);
        inputs.push_back(std::move(*input));
    }
    for (const Input& input : inputs)
        if (input.kind != inputs.front().kind)
            return Fail("sweep files and histories mixed: " + inputs.front().path + " and " + input.path, kExitUsage);
    // DIR is created and probed (a full or read-only disk is named before anything is written); links in
    // its path are followed, since the user named it, and none at the names written in it (Session::WriteText).
    if (Status writable = CheckWritableFolder(options.outDir); !writable)
        return Fail(writable.error().message, kExitFailed);
    return inputs.front().kind == InputKind::Sweep ? MergeSweeps(inputs, options.outDir)
                                                   : MergeHistories(inputs, options.outDir);
}

const CommandRegistration kRegistration({
    .name = "merge",
    .summary = "Combine the files of sweep --shard I/N into one sweep, or histories into one",
    .help = kHelp,
    .helpOrder = 7,
    .takesScene = false,
    .takesArguments = true,
    .extraOptions = {TextOption("--out", &CommonOptions::outDir, "--out needs a folder")},
    .run = RunWith(Merge),
});

}  // namespace
}  // namespace cb
