// The performance history (docs/results.md, "Performance history"): JSON
// Lines, one record of `perf record` per line, appended and never rewritten.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "harness/report/InputFormats.h"

namespace cb::perf {

inline constexpr const char* kRecordFormat = "cloudbench-perf/1";

using input::HistoryRecord;

// $CLOUDBENCH_HISTORY, else $XDG_DATA_HOME/cloudbench/history.jsonl, else
// $HOME/.local/share/cloudbench/history.jsonl.
std::string DefaultHistoryPath();

// Every record of the history at `path`, in file order (input::ReadHistory),
// its warnings (lines cut short, skipped) printed to stderr.
Result<std::vector<HistoryRecord>> ReadHistory(const std::string& path);

// Appends `record` as one line: the file (and its folder) created when
// missing, opened O_APPEND, the line written with one write() and fsync()ed.
// When the file does not end with a newline (a line cut short), a newline is
// written first so the new record starts a line of its own.
// Error: "PATH: cannot write: <strerror>".
Status AppendRecord(const std::string& path, const nlohmann::json& record);

// The record `selector` names in `records`: "-N" the N-th from the end (-1 the
// last), otherwise a record's "id", or a prefix of exactly one id.
// Error: "PATH@SELECTOR: ..." naming what is wrong.
Result<const HistoryRecord*> SelectRecord(const std::vector<HistoryRecord>& records, const std::string& path,
                                          const std::string& selector);

// The records `selector` names, in file order: one record as SelectRecord, or
// "A:B" every record from A to B inclusive, each end as SelectRecord (an empty
// A the first record, an empty B the last). Error: "PATH@SELECTOR: ..." naming
// what is wrong, including a range whose A comes after its B.
Result<std::vector<const HistoryRecord*>> SelectRecords(const std::vector<HistoryRecord>& records,
                                                        const std::string& path, const std::string& selector);

// A new record id: the UTC time, compact, and 6 random hex digits ("20260101T120000Z-3fa2c1").
std::string NewRecordId();

}  // namespace cb::perf
