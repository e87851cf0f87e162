// What `accuracy` and `sweep` measure, as rows: a setting x backend x stage,
// its time and error, and the forms the report and the JSON give them
// (docs/results.md).
#pragma once

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "harness/accuracy/Accuracy.h"
#include "harness/accuracy/Evaluator.h"
#include "harness/report/ReportModel.h"
#include "harness/run/Session.h"

namespace cb {

// One measured row: a setting (list of overrides) x backend x stage.
struct Row {
    std::vector<SceneOverride> settings;
    std::string backend;
    Stage stage = Stage::Shade;
    StageAccuracy result;
    bool pareto = false;
    bool paretoTie = false;  // on the front, and tied with another row on it (MarkPareto)
};

// "(scene)" for no settings, else "path=value path=value".
std::string SettingsLabel(const std::vector<SceneOverride>& settings);

// The row's columns (ErrorColumns) from the backend on; a row that was not
// measured has its status and detail in the time column.
std::vector<report::Cell> RowCells(const Row& row);
// The columns of `first`, then backend, time and the error statistics over
// all elements and over the stage's subset (in cloud, under cloud).
std::vector<report::Column> ErrorColumns(std::initializer_list<std::string> first, Stage stage);
// How the tables print an error statistic and a PSNR (sweep.md, accuracy.md, the CLI's tables).
inline constexpr const char* kErrorFormat = "%.3g";
inline constexpr const char* kPsnrFormat = "%.2f";

// The error statistics columns alone ("max", "mean", "p99", with `suffix`).
std::vector<report::Column> StatsColumns(const std::string& suffix = "");
std::vector<report::Cell> StatsCells(const ErrorStats& e);

// A time summary as the JSON rows give it: median_ms, q1_ms, q3_ms, min_ms, max_ms, count.
nlohmann::json TimeJson(const Summary& s);
nlohmann::json RowJson(const Row& row);
nlohmann::json StatsJson(const ErrorStats& e);
nlohmann::json ReferencesJson(const std::vector<ReferenceRecord>& records, int threads);
// The table of the references' build time and speed.
report::Table ReferenceSpeedTable(const std::vector<ReferenceRecord>& records);

// A pipe table of text columns titled `titles`.
report::Table TextTable(std::initializer_list<std::string> titles);

}  // namespace cb
