#include "harness/report/InputFormats.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "core/base/JsonDom.h"
#include "core/base/NamedValues.h"
#include "core/base/ShownText.h"
#include "core/scene/Stage.h"
#include "core/plan/StageGraph.h"
#include "harness/report/PerfSchemas.h"

namespace cb::input {
namespace {

using namespace schema;
using nlohmann::json;

constexpr double kMaxCount = 9007199254740992.0;  // 2^53: the largest count a JSON reader holds exactly
constexpr double kMaxSteps = 4294967295.0;        // steps are uint32


Node Count() { return Integer(0, kMaxCount); }
Node Step() { return Integer(0, kMaxSteps); }
Node Ms() { return Number(0, kMaxSampleMs); }
Node Samples() { return ArrayOf(Ms()); }
Node Names() { return ArrayOf(Text()); }
Node Fraction() { return Number(0, 1); }
// An error statistic: a number, or "nan", "inf", "-inf" for the values JSON cannot hold
// (harness/platform/TransferJson.h).
Node Statistic() { return NumberOrNonFinite(); }

// A summary of samples (harness/report/ResultsJson.cpp SummaryJson): the samples, which readers need, and their order
// statistics, which they can do without (a reader computes them from the samples).
std::vector<Field> SummaryFields(bool withSamples) {
    std::vector<Field> fields = {{"median_ms", Ms()}, {"q1_ms", Ms()},  {"q3_ms", Ms()},
                                 {"min_ms", Ms()},    {"max_ms", Ms()}, {"count", Count()}};
    if (withSamples) fields.insert(fields.begin(), {"samples_ms", Samples(), true});
    return fields;
}
Node Summary() { return Object(SummaryFields(true)); }
// A stage's wall-time summary with its CPU and device times beside it.
Node SummaryWithClocks() {
    std::vector<Field> fields = SummaryFields(true);
    fields.push_back({"cpu", Summary()});
    fields.push_back({"device", Summary()});
    return Object(std::move(fields));
}
Node CountSummary() {
    return Object({{"median", Number(0, kMaxCount), true},
                   {"min", Number(0, kMaxCount), true},
                   {"max", Number(0, kMaxCount), true}});
}

const std::vector<std::string>& BackendStatuses() {
    static const std::vector<std::string> statuses = {
        "ok", "failed", "crashed", "timed out", "out of memory", "unavailable", "unsupported"};
    return statuses;
}

Node Provenance() {
    const Node backend = Object({{"name", Text(), true},
                                 {"status", Text()},
                                 {"device", Text()},
                                 {"reason", Text()},
                                 {"driver", Text()},
                                 {"api", Text()}});
    return OpenObject({
        {"git", Object({{"commit", Text()}, {"dirty", AnyValue()}})},
        {"build", Object({{"version", Text()}, {"type", Text()}, {"flags", Text()}, {"compiler", Text()}})},
        {"machine", OpenObject({{"cpu", Text()}, {"threads", Count()}, {"os", Text()}})},
        {"date", Text()},
        {"backends", ArrayOf(backend)},
        {"command_line", Names()},
        {"scene", OpenObject({{"path", Text()},
                              {"name", Text()},
                              {"overrides", ArrayOf(Object({{"path", Text(), true}, {"value", Text(), true}}))},
                              {"resolved", AnyValue()}})},
        {"shards", AnyValue()},
    });
}

// The `report` block every JSON output carries (harness/report/ReportModel.cpp RenderJson), which `report` reads back.
Node ReportBlock() {
    const Node column =
        Object({{"title", Text(), true}, {"type", TextOf({"text", "real", "integer"})}, {"unit", Text()}});
    const Node table = Object(
        {{"columns", ArrayOf(column), true}, {"rows", ArrayOf(ArrayOf(Either(Text(), Nullable(Number())))), true}});
    const Node block = Object({{"table", table},
                               {"key_values", ArrayOf(Object({{"key", Text(), true}, {"value", Text(), true}}))},
                               {"paragraph", Text()},
                               {"image", Object({{"path", Text(), true}, {"caption", Text()}})},
                               {"link", Object({{"target", Text(), true}, {"text", Text()}})},
                               {"figure", Object({{"kind", Text(), true}, {"caption", Text()}})}});
    const Node section = Object({{"title", Text(), true}, {"blocks", ArrayOf(block), true}});
    return Object({{"title", Text(), true}, {"sections", ArrayOf(section), true}});
}

Node FrameCamera(std::span<const FrameCounterField> counters) {
    std::vector<Field> fields = SummaryFields(true);
    fields.push_back({"steps", ArrayOf(Step()), true});
    fields.push_back({"alphas", ArrayOf(Fraction()), true});
    fields.push_back({"fps_median", Number(0, 1e12), true});
    for (const FrameCounterField& c : counters)
        if (c.shown != CounterShown::ReadBack) fields.push_back({std::string(c.name), ArrayOf(Count()), true});
    return Object(std::move(fields));
}

Node TimingMode(const char* callTime) {
    const Node call = Object({{callTime, Summary(), true}, {"cpu", Summary()}, {"device", Summary()}});
    return Object({{"steps", Count(), true},
                   {"step_ms", Summary(), true},
                   {"submissions", CountSummary(), true},
                   {"host_waits", CountSummary(), true},
                   {"batches", CountSummary(), true},
                   {"stages", MapOf(KeyRule::Stage, call), true},
                   {"frames", MapOf(KeyRule::Any, call)}});
}

Node ResultsBackend() {
    std::vector<Field> loopStep = SummaryFields(true);
    std::vector<Field> frameMs = SummaryFields(true);
    frameMs.push_back(
        {"slowest", Object({{"step", Step(), true}, {"frame", Count(), true}, {"work", Text(), true}}), true});
    const Node loop = Object({{"steps", Count(), true},
                              {"frames", Count(), true},
                              {"wall_ms", Number(0, 1e15), true},
                              {"fps", Nullable(Number(0, 1e12)), true},
                              {"steps_per_second", Nullable(Number(0, 1e12)), true},
                              {"step_ms", Object(loopStep), true},
                              {"slices_per_frame", Count(), true},
                              {"frame_ms", Object(frameMs)}});
    const Node stageRuns = Object({{"ran", Count(), true},
                                   {"skipped_unchanged", Count(), true},
                                   {"not_output_step", Count(), true},
                                   {"frames", Count()}});
    const Node failure = Object({{"status", TextOf(BackendStatuses()), true},
                                 {"signal", Text()},
                                 {"stage", Text()},
                                 {"step", Nullable(Step())},
                                 {"message", Text()}});
    std::vector<Field> fields{
        {"status", TextOf(BackendStatuses()), true},
        {"error", Text()},
        {"failure", failure},
        {"device", Text()},
        {"planned_bytes", Count()},
        {"steps_completed", Count()},
        {"stages", MapOf(KeyRule::Stage, SummaryWithClocks())},
        {"host", MapOf(KeyRule::Any, Summary())},
        {"transfers", MapOf(KeyRule::Any, Summary())},
        {"stage_runs", MapOf(KeyRule::Stage, stageRuns)},
        {"loop", loop},
        {"cover", ArrayOf(Fraction())},
        {"cover_summary", Object({{"mean", Fraction(), true},
                                  {"median", Fraction(), true},
                                  {"min", Fraction(), true},
                                  {"max", Fraction(), true}})},
        {"timing", Object({{"mode", TextOf({"synchronized", "pipelined", "both"}), true},
                           {"synchronized", TimingMode("wall")},
                           {"pipelined", TimingMode("host")}})},
    };
    // Each renderer's frames, per camera (harness/report/ResultsJson.cpp).
    for (Stage stage : kAllStages)
        if (const RendererDescriptor* renderer = Describe(stage).renderer)
            fields.push_back({std::string(renderer->resultsKey), MapOf(KeyRule::PathName, FrameCamera(renderer->counters))});
    return Object(std::move(fields));
}

Node ResultsSchema() {
    const Node scene = Object({{"name", Text(), true},
                               {"path", Text()},
                               {"grid", ArrayOf(Integer(1, kMaxCount), 3, 3)},
                               {"steps", Step()},
                               {"warmup_steps", Step()},
                               {"frames_per_step", Count()},
                               {"sun_moves", Boolean()},
                               {"stages", ArrayOf(TextOf(detail::SchemaStageNames()))}});
    return Object({{"format", TextOf({"cloudbench-results/1"}), true},
                   {"scene", scene, true},
                   {"backends", MapOf(KeyRule::Backend, ResultsBackend()), true},
                   {"pending", ArrayOf(Text())},
                   {"complete", Boolean()},
                   {"files", ArrayOf(Name())},
                   {"report", ReportBlock()},
                   {"provenance", Provenance()}});
}

// scene -> backend -> stage -> what a history record or a count output holds per stage.
Node ByStage(Node leaf) { return MapOf(KeyRule::PathName, MapOf(KeyRule::Backend, MapOf(KeyRule::Stage, leaf))); }

Node InstructionsSection() { return ByStage(Integer(0, 1e19)); }

Node PerfRecordSchema() {
    // A report tolerates a missing median (it uses the samples'); perf compare needs the samples.
    const Node times =
        Object({{"samples_ms", Samples(), true}, {"median_ms", Nullable(Ms())}, {"runs_ms", ArrayOf(Samples())}});
    // The wall times, with the same runs' CPU times beside them ("cpu", from cloudbench 2026-12 on).
    const Node result = Object({{"samples_ms", Samples(), true},
                                {"median_ms", Nullable(Ms())},
                                {"runs_ms", ArrayOf(Samples())},
                                {"cpu", times}});
    // An object naming any of scene, backend and stage, or the text "scene/backend/stage" (docs/cli.md, "report").
    const Node changePoint = Either(OpenObject({{"scene", Text()}, {"backend", Text()}, {"stage", Text()}}), Text());
    return Object({{"format", TextOf({"cloudbench-perf/1"}), true},
                   {"id", Text(), true},
                   {"time", Text()},
                   {"provenance", Provenance()},
                   {"suite", ArrayOf(Object({{"scene", Text(), true}, {"set", Names()}}))},
                   {"repeat", Integer(1, 1e6)},
                   {"seconds", Number(0, 1e12)},
                   {"results", ByStage(result), true},
                   {"failures", MapOf(KeyRule::PathName, MapOf(KeyRule::Backend, Text()))},
                   {"instructions", InstructionsSection()},
                   {"instructions_not_counted", Text()},
                   {"change_points", ArrayOf(changePoint)}});
}

Node CountSchema() {
    return Object({{"format", TextOf({"cloudbench-count/1"}), true},
                   {"tool", AnyValue()},
                   {"scene", Text()},
                   {"steps", Step()},
                   {"warmup_steps", Step()},
                   {"counted_steps", ArrayOf(Step(), 2, 2)},
                   {"instructions", InstructionsSection(), true},
                   {"per_step", ByStage(MapOf(KeyRule::Any, Integer(0, 1e19)))},
                   {"wall_s", MapOf(KeyRule::Backend, Number(0, 1e12))},
                   {"report", ReportBlock()},
                   {"provenance", Provenance()}});
}

// A file of instruction counts alone, for perf record --instructions and perf compare.
Node InstructionsSchema() {
    return Object({{"instructions", InstructionsSection(), true}, {"provenance", Provenance()}});
}

Node ErrorStats() {
    return Object({{"count", Count(), true},
                   {"max", Statistic(), true},
                   {"mean", Statistic(), true},
                   {"p99", Statistic(), true},
                   {"worst_index", Count()},
                   {"worst", Count()}});
}

// A row of sweep.json and accuracy.json (harness/accuracy/Measurement.cpp RowJson).
Node MeasuredRow() {
    return Object({{"settings", MapOf(KeyRule::Any, Text()), true},
                   {"backend", Text(), true},
                   {"stage", TextOf(detail::SchemaStageNames()), true},
                   {"status", Text(), true},
                   {"detail", Text()},
                   {"time", Object(SummaryFields(false))},
                   {"error", Object({{"all", ErrorStats(), true},
                                     {"in_cloud", ErrorStats()},
                                     {"under_cloud", ErrorStats()},
                                     {"psnr_db", Nullable(Statistic())}})},
                   {"pareto", Boolean()},
                   {"pareto_tie", Boolean()}});
}

// A row of a shard (harness/accuracy/AccuracyTransfer.h ToJson(Row)), read back by merge.
Node ShardRow() {
    const Node summary = Object({{"count", Count(), true},
                                 {"median", Statistic(), true},
                                 {"q1", Statistic(), true},
                                 {"q3", Statistic(), true},
                                 {"min", Statistic(), true},
                                 {"max", Statistic(), true}});
    return Object({{"settings", ArrayOf(ArrayOf(Text(), 2, 2)), true},
                   {"backend", Text(), true},
                   {"stage", TextOf(detail::SchemaStageNames()), true},
                   {"status", Text(), true},
                   {"detail", Text(), true},
                   {"time", summary, true},
                   {"all", ErrorStats(), true},
                   {"subset", ErrorStats(), true},
                   {"pareto", Boolean(), true},
                   {"psnr_db", Nullable(Statistic()), true},
                   {"point", Count(), true}});
}

Node SweepSchema() {
    const Node shard = Object({{"index", Integer(1, 1e9), true},
                               {"count", Integer(1, 1e9), true},
                               {"points", Count(), true},
                               {"rows", ArrayOf(ShardRow()), true}});
    return Object({{"format", TextOf({"cloudbench-sweep/1"}), true},
                   {"scene", Text(), true},
                   {"grid", ArrayOf(Integer(1, kMaxCount), 3, 3)},
                   {"step", Step()},
                   {"metric", Text(), true},
                   {"repeats", Integer(1, 1e9)},
                   {"reference_start", Text()},
                   {"references", AnyValue()},
                   {"vary", ArrayOf(Object({{"path", Text(), true}, {"values", Names(), true}})), true},
                   {"rows", ArrayOf(MeasuredRow()), true},
                   {"within", Object({{"bound", Statistic(), true}, {"fastest", ArrayOf(MeasuredRow()), true}})},
                   {"shard", shard},
                   {"report", ReportBlock()},
                   {"provenance", Provenance()}});
}

Node ConformSchema() {
    const Node row = Object({{"case", Text()},
                             {"stage", Text(), true},
                             {"backend", Text(), true},
                             {"status", Text(), true},
                             {"rule", Text()},
                             {"worst", Statistic()},
                             {"tolerance", Statistic()},
                             {"where", AnyValue()},
                             {"detail", Text()},
                             {"difference_image", Text()},
                             {"reruns", AnyValue()}});
    return Object({{"format", TextOf({"cloudbench-conform/1"}), true},
                   {"scene", Text(), true},
                   {"steps", Step()},
                   {"results", ArrayOf(row), true},
                   {"coverage", AnyValue()},
                   {"cases", AnyValue()},
                   {"flake_reruns", Count()},
                   {"baseline", Text()},
                   {"report", ReportBlock()},
                   {"provenance", Provenance()}});
}

Node AccuracySchema() {
    return Object({{"format", TextOf({"cloudbench-accuracy/1"}), true},
                   {"scene", Text(), true},
                   {"grid", ArrayOf(Integer(1, kMaxCount), 3, 3)},
                   {"step", Step()},
                   {"reference_start", Text()},
                   {"repeats", Integer(1, 1e9)},
                   {"rows", ArrayOf(MeasuredRow()), true},
                   {"voxel_centre_reference", AnyValue()},
                   {"voxel_exit_vs_centre", AnyValue()},
                   {"switches", AnyValue()},
                   {"image_rows", AnyValue()},
                   {"image_references", AnyValue()},
                   {"reference_step_voxels", Number(0, 1)},
                   {"references", AnyValue()},
                   {"report", ReportBlock()},
                   {"provenance", Provenance()}});
}

Node SuiteSchema() {
    return Object({{"scenes", ArrayOf(Object({{"scene", Text(), true}, {"set", Names()}}), 1), true}});
}

struct Described {
    Format format;
    std::string_view name, noun;  // name: its "format" value; "" for a format recognised by its shape
    Node (*schema)();
    std::string_view shapeKey = {};  // a format without a name: the key a document of it has
};

const Described kFormats[] = {
    {Format::Results, "cloudbench-results/1", "a results.json", ResultsSchema},
    {Format::PerfRecord, "cloudbench-perf/1", "a perf history record", PerfRecordSchema},
    {Format::Count, "cloudbench-count/1", "a count output", CountSchema},
    {Format::Instructions, "", "an instruction file", InstructionsSchema, "instructions"},
    {Format::Sweep, "cloudbench-sweep/1", "a sweep.json", SweepSchema},
    {Format::Conform, "cloudbench-conform/1", "a conform.json", ConformSchema},
    {Format::Accuracy, "cloudbench-accuracy/1", "an accuracy.json", AccuracySchema},
    {Format::Suite, "", "a perf suite", SuiteSchema, "scenes"},
    {Format::Interleave, "cloudbench-interleave/1", "a kept interleave's interleave.json", detail::InterleaveSchema},
    {Format::PerfCompare, "cloudbench-perf-compare/1", "a perf compare --json file", detail::PerfCompareSchema},
};

const Described& Lookup(Format format) {
    for (const Described& d : kFormats)
        if (d.format == format) return d;
    return kFormats[0];
}

// The format `doc` is: by "format", or by its shape for the two without one.
std::optional<Format> Recognise(const json& doc) {
    if (!doc.is_object()) return std::nullopt;
    const auto it = doc.find("format");
    if (it != doc.end()) {
        for (const Described& d : kFormats)
            if (!d.name.empty() && *it == d.name) return d.format;
        return std::nullopt;
    }
    for (const Described& d : kFormats)
        if (d.name.empty() && doc.contains(d.shapeKey)) return d.format;
    return std::nullopt;
}

// The keys a document of one of `formats` is recognised by: "\"format\"", "\"scenes\"", "\"format\" or
// \"instructions\"".
std::string IdentifyingKeys(std::span<const Format> formats) {
    std::vector<std::string_view> keys;
    for (Format format : formats) {
        const Described& d = Lookup(format);
        const std::string_view key = d.name.empty() ? d.shapeKey : "format";
        if (std::ranges::find(keys, key) == keys.end()) keys.push_back(key);
    }
    std::string out;
    for (size_t i = 0; i < keys.size(); ++i)
        out += (i == 0 ? "" : i + 1 == keys.size() ? " or " : ", ") + QuoteShown(keys[i]);
    return out;
}

std::string Nouns(std::span<const Format> formats) {
    std::string out;
    for (size_t i = 0; i < formats.size(); ++i)
        out += (i == 0 ? "" : i + 1 == formats.size() ? " or " : ", ") + std::string(Lookup(formats[i]).noun);
    return out;
}

}  // namespace

schema::Node detail::ProvenanceSchema() { return Provenance(); }

const std::vector<std::string>& detail::SchemaStageNames() {
    static const std::vector<std::string> names = [] {
        std::vector<std::string> all;
        for (Stage stage : kAllStages) all.emplace_back(StageName(stage));
        return all;
    }();
    return names;
}
schema::Node detail::ReportBlockSchema() { return ReportBlock(); }

std::string_view FormatName(Format format) { return Lookup(format).name; }
std::string_view FormatNoun(Format format) { return Lookup(format).noun; }

const schema::Node& SchemaOf(Format format) {
    static const std::vector<schema::Node> schemas = [] {
        std::vector<schema::Node> all;
        for (const Described& d : kFormats) all.push_back(d.schema());
        return all;
    }();
    for (size_t i = 0; i < std::size(kFormats); ++i)
        if (kFormats[i].format == format) return schemas[i];
    return schemas[0];
}

namespace {

// For a document with no "format" that no accepted format recognises: its first key that none of them has and
// that is a typo of one of their top-level fields ("scens" for a perf suite's "scenes"), as the schema names an
// unknown field: "/scens: unknown field (did you mean "scenes"?)". nullopt when no key is that close. A typo
// here is at most one edit in three letters of the shorter name ("fromat", not "foo" for "tool"): stricter than
// a schema's "did you mean", because it decides which format the document was meant to be.
std::optional<std::string> MisspelledKey(const json& doc, std::span<const Format> accepted) {
    if (!doc.is_object() || doc.contains("format")) return std::nullopt;
    std::vector<std::string_view> known;
    for (Format format : accepted)
        for (std::string_view name : FieldNames(SchemaOf(format))) known.push_back(name);
    constexpr size_t kMaxKeyChars = 64;  // EditDistance is quadratic
    for (const auto& [key, value] : doc.items()) {
        if (key.size() > kMaxKeyChars || std::ranges::find(known, key) != known.end()) continue;
        for (std::string_view name : known)
            if (3 * EditDistance(key, name) <= std::min(key.size(), name.size()))
                return "/" + scene_io::PointerToken(key) + ": unknown field (did you mean " + QuoteShown(name) + "?)";
    }
    return std::nullopt;
}

// `text` (from `path`) as one document of `accepted`; the errors of ReadCloudbenchFile. `orHistory`: a history
// would do too, and the messages say so.
Result<Document> ParseDocument(const std::string& text, const std::string& path, std::span<const Format> accepted,
                               scene_io::JsonDocument& doc, bool orHistory = false) {
    const std::string nouns = Nouns(accepted) + (orHistory ? ", nor a perf history" : "");
    if (doc.failure)
        return MakeError(path + ": not " + nouns + ": " + scene_io::DescribeParseFailure(text, *doc.failure));
    if (!doc.duplicates.empty())
        return MakeError(path + ": " + ShownText(doc.duplicates.front(), false, 200) + ": duplicate key");
    const std::optional<Format> format = Recognise(doc.root);
    if (!format || std::ranges::find(accepted, *format) == accepted.end()) {
        if (std::optional<std::string> misspelled = MisspelledKey(doc.root, accepted); misspelled && !format)
            return MakeError(path + ": " + *misspelled);
        std::string found = "not a JSON object";
        if (doc.root.is_object()) {
            const auto it = doc.root.find("format");
            found = it == doc.root.end() ? "no " + IdentifyingKeys(accepted)
                    : it->is_string()    ? "\"format\" is " + QuoteShown(it->get_ref<const std::string&>())
                                         : "\"format\" is not a string";
        }
        return MakeError(path + ": not " + nouns + " (" + found + ")");
    }
    CB_TRY(schema::Validate(doc.root, SchemaOf(*format), path));
    return Document{*format, std::move(doc.root)};
}

Result<History> ParseHistory(const std::string& text, const std::string& path) {
    History history;
    size_t skipped = 0;
    bool first = true;
    for (size_t at = 0, line = 1; at < text.size(); ++line) {
        size_t end = text.find('\n', at);
        if (end == std::string::npos) end = text.size();
        const std::string content = text.substr(at, end - at);
        at = end + 1;
        if (content.find_first_not_of(" \t\r") == std::string::npos) continue;
        const std::string label = path + ":" + std::to_string(line);
        scene_io::JsonDocument doc = scene_io::ParseJsonDocument(content);
        if (doc.failure || !doc.root.is_object()) {
            // The first line decides whether this is a history at all: a results.json (pretty-printed, so its
            // first line is "{"), a truncated file or another file is refused, not skipped line by line.
            if (first)
                return MakeError(path + ": not a perf history (JSON Lines of cloudbench-perf/1 records): line " +
                                 std::to_string(line) + " is not a JSON object");
            if (++skipped <= kMaxHistoryWarnings)
                history.warnings.push_back(label + ": skipped: not JSON (a write cut short?)");
            continue;
        }
        first = false;
        if (!doc.duplicates.empty())
            return MakeError(label + ": " + ShownText(doc.duplicates.front(), false, 200) + ": duplicate key");
        if (Recognise(doc.root) != Format::PerfRecord) {
            static constexpr Format kRecord[] = {Format::PerfRecord};
            if (std::optional<std::string> misspelled = MisspelledKey(doc.root, kRecord))
                return MakeError(label + ": " + *misspelled);
            return MakeError(label + ": not a cloudbench-perf/1 record (a perf history holds only records)");
        }
        CB_TRY(schema::Validate(doc.root, SchemaOf(Format::PerfRecord), label));
        history.records.push_back({line, std::move(doc.root)});
    }
    if (skipped > kMaxHistoryWarnings)
        history.warnings.push_back(path + ": " + std::to_string(skipped - kMaxHistoryWarnings) +
                                   " more lines skipped: not JSON");
    return history;
}

}  // namespace

Result<Document> ReadCloudbenchFile(const std::string& path, std::span<const Format> accepted) {
    Result<std::string> text = ReadInputFile(path, kDocumentInput);
    if (!text) return std::unexpected(text.error());
    scene_io::JsonDocument doc = scene_io::ParseJsonDocument(*text);
    return ParseDocument(*text, path, accepted, doc);
}

Result<Document> ReadCloudbenchFileBeneath(const std::string& folder, const std::string& name,
                                           std::span<const Format> accepted) {
    Result<std::string> text = ReadInputBeneath(folder, name, kDocumentInput);
    if (!text) return std::unexpected(text.error());
    scene_io::JsonDocument doc = scene_io::ParseJsonDocument(*text);
    return ParseDocument(*text, (std::filesystem::path(folder) / name).string(), accepted, doc);
}

void PrintWarnings(const History& history) {
    for (const std::string& warning : history.warnings) std::fprintf(stderr, "warning: %s\n", warning.c_str());
}

Result<History> ReadHistory(const std::string& path) {
    Result<std::string> text = ReadInputFile(path, kHistoryInput);
    if (!text) return std::unexpected(text.error());
    return ParseHistory(*text, path);
}

Result<std::variant<Document, History>> ReadDocumentOrHistory(const std::string& path,
                                                              std::span<const Format> accepted) {
    Result<std::string> text = ReadInputFile(path, kHistoryInput);
    if (!text) return std::unexpected(text.error());
    scene_io::JsonDocument doc = scene_io::ParseJsonDocument(*text);
    // One JSON value is a document, except a record alone, which is a history of one; JSON Lines (more than one
    // value) are a history. A text that is neither is named as the documents would name it when its first line
    // is not a record either.
    if (!doc.failure && Recognise(doc.root) != Format::PerfRecord) {
        Result<Document> one = ParseDocument(*text, path, accepted, doc, /*orHistory=*/true);
        if (!one) return std::unexpected(one.error());
        return std::variant<Document, History>(std::move(*one));
    }
    const size_t firstLineEnd = text->find('\n');
    scene_io::JsonDocument firstLine = scene_io::ParseJsonDocument(text->substr(0, firstLineEnd));
    // A first line that is a record but for a misspelled key is a history's, and ParseHistory names the key.
    static constexpr Format kRecord[] = {Format::PerfRecord};
    const bool firstIsRecord = !firstLine.failure && (Recognise(firstLine.root) == Format::PerfRecord ||
                                                      MisspelledKey(firstLine.root, kRecord).has_value());
    if (doc.failure && !firstIsRecord) {
        Result<Document> one = ParseDocument(*text, path, accepted, doc, /*orHistory=*/true);
        return MakeError(one.error().message + " (its first line is not a record either)");
    }
    Result<History> history = ParseHistory(*text, path);
    if (!history) return std::unexpected(history.error());
    return std::variant<Document, History>(std::move(*history));
}

}  // namespace cb::input
