// `cloudbench perf export` (docs/cli.md, "perf"): writes results files, run
// folders or history records as Google Benchmark's JSON for compare.py.
#include <cmath>
#include <cstdio>
#include <numeric>

#include "harness/commands/PerfCommon.h"

namespace cb::perf_command {
namespace {

// Google Benchmark's JSON for repetitions (what --benchmark_repetitions=N
// --benchmark_format=json writes), one benchmark per scene/backend/stage: a
// run is a repetition and its steps are its iterations, so each "iteration"
// row holds one run's mean time per step (Google Benchmark's own per-repetition
// value), followed by the "_mean", "_median" and "_stddev" aggregates over the
// runs. compare.py's U test then draws on runs, the unit that varies (it needs
// two repetitions a side, and asks for nine). Every row is in microseconds, one
// unit whatever the times, since compare.py drops a benchmark whose unit
// differs between its two files. cpu_time repeats the wall time: cloudbench
// measures no CPU time.
json GbenchJson(const perf::Side& side) {
    const json& p = side.provenance;
    const json machine = p.is_object() ? p.value("machine", json::object()) : json::object();
    json doc = {{"context",
                 {{"date", side.date},
                  {"host_name", machine.value("cpu", "")},
                  {"executable", "cloudbench " + side.label},
                  {"num_cpus", machine.value("threads", 0)},
                  {"mhz_per_cpu", 0},
                  {"cpu_scaling_enabled", false},
                  {"caches", json::array()},
                  {"library_build_type", "release"}}},
                {"benchmarks", json::array()}};
    int family = 0;
    for (const auto& [scene, backends] : side.runs)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, runs] : stages) {
                const std::string name = scene + "/" + backend + "/" + stage;
                std::vector<double> usPerStep;
                std::vector<size_t> steps;
                for (const perf::RunSamples& run : runs)
                    if (!run.ms.empty()) {
                        usPerStep.push_back(std::accumulate(run.ms.begin(), run.ms.end(), 0.0) * 1000 /
                                            double(run.ms.size()));
                        steps.push_back(run.ms.size());
                    }
                if (usPerStep.empty()) continue;
                auto row = [&](const std::string& rowName, const char* type, double us, size_t iterations) {
                    return json{{"name", rowName},  {"family_index", family},   {"per_family_instance_index", 0},
                                {"run_name", name}, {"run_type", type},         {"repetitions", usPerStep.size()},
                                {"threads", 1},     {"iterations", iterations}, {"real_time", us},
                                {"cpu_time", us},   {"time_unit", "us"}};
                };
                for (size_t i = 0; i < usPerStep.size(); ++i) {
                    json r = row(name, "iteration", usPerStep[i], steps[i]);
                    r["repetition_index"] = i;
                    doc["benchmarks"].push_back(r);
                }
                const double n = double(usPerStep.size());
                const double mean = std::accumulate(usPerStep.begin(), usPerStep.end(), 0.0) / n;
                double squares = 0;
                for (double v : usPerStep) squares += (v - mean) * (v - mean);
                const double stddev = usPerStep.size() > 1 ? std::sqrt(squares / (n - 1)) : 0;
                for (auto [aggregate, value] : {std::pair{"mean", mean}, std::pair{"median", perf::Median(usPerStep)},
                                                std::pair{"stddev", stddev}}) {
                    json r = row(name + "_" + aggregate, "aggregate", value, usPerStep.size());
                    r["aggregate_name"] = aggregate;
                    r["aggregate_unit"] = "time";
                    doc["benchmarks"].push_back(r);
                }
                ++family;
            }
    return doc;
}

}  // namespace

int Export(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--gbench"}, {}, a)) return Usage(*m);
    if (!a.Has("--gbench")) return Usage("perf export needs --gbench OUT");
    if (a.positional.empty()) return Usage("perf export needs a SOURCE");
    // Several sources are one side, their runs pooled.
    perf::Side side;
    for (const std::string& source : a.positional) {
        if (source.empty()) return Usage("perf export: SOURCE must not be empty");
        auto one = perf::LoadSide(source);
        if (!one) {
            std::fprintf(stderr, "%s\n", one.error().message.c_str());
            return kExitBadScene;
        }
        if (side.label.empty()) {
            side = std::move(*one);
            continue;
        }
        side.label += " " + one->label;
        for (auto& [scene, backends] : one->runs)
            for (auto& [backend, stages] : backends)
                for (auto& [stage, runs] : stages) {
                    auto& into = side.runs[scene][backend][stage];
                    into.insert(into.end(), runs.begin(), runs.end());
                }
    }
    return WriteJsonFile(a.Value("--gbench"), GbenchJson(side)) ? kExitOk : kExitFailed;
}

}  // namespace cb::perf_command
