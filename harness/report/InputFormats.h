// The JSON files cloudbench writes and other commands read back, as schemas
// (harness/platform/JsonInput.h), and the one reader of each: results.json (perf
// compare, perf record, report), a perf history and its records (perf
// compare, history, export, merge, report), a kept interleave's manifest
// (perf compare, export), `perf compare --json` (report), count outputs and instruction files (perf compare,
// perf record --instructions), sweep.json and its shards (merge, report),
// conform.json and accuracy.json (report) and perf suites (perf record
// --suite). docs/results.md describes the formats; a field
// cloudbench writes is added here in the same change (the bad-input corpus,
// tests/check_bad_inputs.py, reads real outputs back through these schemas).
// A field is required when a reader cannot use the file without it (a
// results.json's scene name and each backend's status, a stage's samples);
// every other field is optional, and of its type and range when present.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/base/Error.h"
#include "harness/platform/JsonInput.h"

namespace cb::input {

// The largest time a sample may hold, in ms (11.6 days): a stage call that takes longer is not a measurement.
inline constexpr double kMaxSampleMs = 1e9;

// The formats, by their "format" field.
enum class Format { Results, PerfRecord, Count, Instructions, Sweep, Conform, Accuracy, Suite, Interleave, PerfCompare };

// The "format" a file of `format` declares ("cloudbench-results/1"); "" for Instructions and Suite, which have
// none.
std::string_view FormatName(Format format);
// What the file is, for messages: "a results.json", "a perf history record".
std::string_view FormatNoun(Format format);

const schema::Node& SchemaOf(Format format);

// A document of one of the formats, checked against its schema.
struct Document {
    Format format;
    nlohmann::json doc;
};

// The JSON file at `path` (at most kDocumentInput's size), which must be one of `accepted` (by its "format", or
// by its shape for the formats without one), checked against that format's schema. Errors name the file and
// the field: "PATH: not a results.json or a count output ("format" is "cloudbench-sweep/1")", "PATH:
// /backends/cpu/stages/region/samples_ms/3: must be a number in [0, 1e+09], got -1".
Result<Document> ReadCloudbenchFile(const std::string& path, std::span<const Format> accepted);
// The same for `name`, found inside the folder `folder`, read beneath it (core/base/PathPolicy.h): a link out of
// the folder is refused. Errors name "FOLDER/NAME".
Result<Document> ReadCloudbenchFileBeneath(const std::string& folder, const std::string& name,
                                           std::span<const Format> accepted);

// One record of a perf history (a line of JSON Lines), with where it was.
struct HistoryRecord {
    size_t line = 0;  // 1-based line in the file
    nlohmann::json record;
};

struct History {
    std::vector<HistoryRecord> records;
    // "PATH:LINE: skipped: not JSON (a write cut short?)" for each line that is not JSON, at most
    // kMaxHistoryWarnings of them and then one line with the count of the rest.
    std::vector<std::string> warnings;
};
inline constexpr size_t kMaxHistoryWarnings = 10;

// Prints the history's warnings to stderr, each as "warning: ...".
void PrintWarnings(const History& history);

// The history at `path` (JSON Lines of cloudbench-perf/1 records; docs/results.md#performance-history). A line
// that is not JSON is a write cut short and is skipped with a warning; a line that is JSON but not a valid record
// is an error ("PATH:12: /results/ci-small/cpu/region/median_ms: must be a number ..."), and so is a file whose
// first line is not a record (it is not a history: a results.json, a truncated file).
Result<History> ReadHistory(const std::string& path);

// For a file that may be either (perf compare's BASE and HEAD, merge's inputs): one JSON document of
// `accepted`, or a history: JSON Lines whose first line is a record, or one record alone.
Result<std::variant<Document, History>> ReadDocumentOrHistory(const std::string& path,
                                                              std::span<const Format> accepted);

}  // namespace cb::input
