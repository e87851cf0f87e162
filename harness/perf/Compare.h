// What `perf compare` compares: the per-step samples of each scene x backend x
// stage (and instruction counts) of two sides, each loaded from a results.json,
// a history record or a `count` output, or pooled from interleaved runs.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "harness/perf/Stats.h"

namespace cb::perf {

template <typename T>
using ByStage = std::map<std::string, std::map<std::string, std::map<std::string, T>>>;  // scene, backend, stage

struct Side {
    std::string label;  // what it was loaded from: "FILE", "FILE@ID"
    std::string date;   // when it was measured (ISO 8601); "" when unknown
    nlohmann::json provenance = nlohmann::json::object();
    ByStage<std::vector<double>> samplesMs;                              // per-step wall times, pooled over runs
    std::map<std::string, std::map<std::string, std::string>> failures;  // scene, backend: why it gave no result
    ByStage<double> instructions;                                        // `cloudbench count`: exact per-stage counts
};

// Adds a results.json document's samples (pooled with any already there),
// its failed backends and, when `side` has none yet, its provenance and date.
// Error: "LABEL: reason" for a document that is not cloudbench-results/1.
Status AddResults(Side& side, const nlohmann::json& results);
// Adds an {"instructions": {scene: {backend: {stage: count}}}} section.
Status AddInstructions(Side& side, const nlohmann::json& doc);

// The side a BASE or HEAD argument names: "FILE" (a results.json, a count
// output or a history, whose last record is taken), "FILE@ID" or "FILE@-N"
// (a history record). Errors name the argument.
Result<Side> LoadSide(const std::string& spec);

// A history record's "results", "failures" and "instructions" sections from a side.
nlohmann::json RecordSections(const Side& side);

struct CompareSettings {
    double threshold = 1.5;  // a slowdown ratio of medians above this (and the rest) is a regression
    // Per backend, instead of `threshold`: OpenGL and Vulkan run on software drivers (llvmpipe, lavapipe)
    // that share the CPU, and moved up to 2.28x between identical builds (reports/perf/walltime.md).
    std::map<std::string, double> backendThreshold = {{"gl", 3.0}, {"vk", 3.0}};
    double separateThreshold = 2.0;  // used instead when the sides were not measured interleaved
    bool interleaved = false;
    double floorMs = 0.05;               // and the medians differ by more than this
    double alpha = 0.01;                 // family-wise, after Holm's correction
    double instructionThreshold = 0.02;  // relative change of an exact count
    double confidence = 0.95;
    int resamples = 2000;
    uint64_t seed = 20260101;
    size_t minSamples = 20;  // fewer on a side: reported, never tested (the normal approximation needs about 20)
};

struct Comparison {
    std::string scene, backend, stage;
    std::string metric;  // "time" (ms) or "instructions"
    size_t baseCount = 0, headCount = 0;
    double baseMedian = NAN, headMedian = NAN, ratio = NAN;  // ratio = head / base
    double threshold = NAN;                                  // the ratio a regression must exceed
    Interval interval{NAN, NAN};
    double pSlower = NAN, pFaster = NAN;          // one-sided Mann-Whitney
    double pSlowerHolm = NAN, pFasterHolm = NAN;  // Holm-adjusted over every time comparison
    char mark = '~';  // + slower, - faster, ~ not significant or small, x failed or missing in HEAD, ! new
    bool regression = false;
    std::string note;
};

struct CompareOutcome {
    std::vector<Comparison> rows;
    double threshold = 0;  // the wall-time threshold applied to backends without their own
    bool separate = false;
    bool headFailed = false;  // some row is 'x'
    size_t Regressions() const;
};

// The wall-time threshold of `backend`: its own or the default, at least
// separateThreshold when the sides were not interleaved.
double ThresholdOf(const CompareSettings& settings, const std::string& backend);

CompareOutcome Compare(const Side& base, const Side& head, const CompareSettings& settings);

}  // namespace cb::perf
