// What `accuracy` and `sweep` share: the Evaluator, which computes the
// lighting stages' inputs (the CPU simulation) and the exact reference once
// per distinct setting, and one setting's shade and shadow stages measured on
// every backend, as rows for the report and the JSON (docs/results.md).
#pragma once

#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "harness/Accuracy.h"
#include "harness/ReportModel.h"
#include "harness/Session.h"

namespace cb {

class ImageReferences;  // harness/ImageAccuracy.h

// printf of one value, for labels and cache keys.
std::string Fmt(const char* format, double value);

struct ReferenceRecord {
    std::string key;  // what the reference was computed for, for a reader
    ref::TraceStats tStats, gStats;
    double buildSeconds = 0;
    size_t primitives = 0;
};

class Evaluator {
  public:
    Evaluator(const Session& session, ref::RayStart start) : mSession(session), mStart(start) {}

    // q and D for a scene loaded with `overrides` (cached by the overrides that can change them).
    Result<const LightingInputs*> Inputs(const Scene& scene, const std::vector<SceneOverride>& overrides);
    // The reference for the last Inputs() and the scene's sun, sigma and h.
    Result<const ReferenceResult*> Reference(const Scene& scene, const LightingInputs& in, ref::RayStart start);
    Result<const ReferenceResult*> Reference(const Scene& scene, const LightingInputs& in) {
        return Reference(scene, in, mStart);
    }

    // The session's scene with `extra` overrides, its inputs and its reference.
    struct Point {
        Scene scene;
        const LightingInputs* in = nullptr;
        const ReferenceResult* reference = nullptr;
    };
    Result<Point> Load(std::span<const SceneOverride> extra);

    const std::vector<ReferenceRecord>& Records() const { return mRecords; }
    const CommonOptions& Options() const { return mSession.Options(); }
    const Session& GetSession() const { return mSession; }
    // The reference renders of this process (harness/ImageAccuracy.h), made on first use.
    ImageReferences& Images();

  private:
    // Bounds memory (a thesis-sized reference is about 11 MB): past kKept
    // entries, all but the last one returned are dropped, so the pointer the
    // caller still holds from the previous call stays valid.
    static constexpr size_t kKept = 8;
    template <typename Map>
    static void KeepOnlyLast(Map& map, const std::string& last) {
        if (map.size() < kKept) return;
        for (auto it = map.begin(); it != map.end();) it = it->first == last ? std::next(it) : map.erase(it);
    }

    const Session& mSession;
    ref::RayStart mStart;
    std::string mLastReference;
    std::map<std::string, LightingInputs> mInputs;
    std::map<std::string, ReferenceResult> mReferences;
    std::vector<ReferenceRecord> mRecords;
    std::string mLastKey;
    std::shared_ptr<ImageReferences> mImages;
};

// One measured row: a setting (list of overrides) x backend x stage.
struct Row {
    std::vector<SceneOverride> settings;
    std::string backend;
    Stage stage = Stage::Shade;
    StageAccuracy result;
    bool pareto = false;
};

// "(scene)" for no settings, else "path=value path=value".
std::string SettingsLabel(const std::vector<SceneOverride>& settings);

// Measures `stages` of one setting on every available backend into `rows`.
Status MeasureSetting(Evaluator& eval, const std::vector<SceneOverride>& setting, std::span<const Stage> stages,
                      std::span<const OpenedBackend> backends, std::vector<Row>& rows);

// The row's columns (ErrorColumns) from the backend on; a row that was not
// measured has its status and detail in the time column.
std::vector<report::Cell> RowCells(const Row& row);
// The columns of `first`, then backend, time and the error statistics over
// all elements and over the stage's subset (in cloud, under cloud).
std::vector<report::Column> ErrorColumns(std::initializer_list<std::string> first, Stage stage);
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
