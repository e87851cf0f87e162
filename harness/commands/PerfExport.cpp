// `cloudbench perf export` (docs/cli.md, "perf"): writes results files, run
// folders or history records as Google Benchmark's JSON for compare.py.
#include <cmath>
#include <cstdio>
#include <numeric>
#include <tuple>

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
// differs between its two files. cpu_time is the process's CPU time over the
// stage's calls, per step, from `cpu` (the same sources on the CPU clock)
// where it has the stage run for run; otherwise (a history) it repeats the wall time.
json GbenchJson(const perf::Side& side, const perf::Side& cpu) {
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
                // Each run's mean step in us, of the runs with steps; `steps` their counts.
                auto meanSteps = [](const std::vector<perf::RunSamples>& of, std::vector<size_t>* steps) {
                    std::vector<double> us;
                    for (const perf::RunSamples& run : of)
                        if (!run.ms.empty()) {
                            us.push_back(std::accumulate(run.ms.begin(), run.ms.end(), 0.0) * 1000 /
                                         double(run.ms.size()));
                            if (steps) steps->push_back(run.ms.size());
                        }
                    return us;
                };
                std::vector<size_t> steps;
                const std::vector<double> usPerStep = meanSteps(runs, &steps);
                if (usPerStep.empty()) continue;
                std::vector<double> cpuPerStep = usPerStep;
                if (auto s = cpu.runs.find(scene); s != cpu.runs.end())
                    if (auto b = s->second.find(backend); b != s->second.end())
                        if (auto st = b->second.find(stage); st != b->second.end())
                            if (auto c = meanSteps(st->second, nullptr); c.size() == usPerStep.size()) cpuPerStep = c;
                auto row = [&](const std::string& rowName, const char* type, double us, double cpuUs,
                               size_t iterations) {
                    return json{{"name", rowName},   {"family_index", family},   {"per_family_instance_index", 0},
                                {"run_name", name},  {"run_type", type},         {"repetitions", usPerStep.size()},
                                {"threads", 1},      {"iterations", iterations}, {"real_time", us},
                                {"cpu_time", cpuUs}, {"time_unit", "us"}};
                };
                for (size_t i = 0; i < usPerStep.size(); ++i) {
                    json r = row(name, "iteration", usPerStep[i], cpuPerStep[i], steps[i]);
                    r["repetition_index"] = i;
                    doc["benchmarks"].push_back(r);
                }
                struct Aggregates {
                    double mean, median, stddev;
                };
                auto aggregates = [](const std::vector<double>& v) {
                    const double n = double(v.size());
                    const double mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
                    double squares = 0;
                    for (double x : v) squares += (x - mean) * (x - mean);
                    return Aggregates{mean, perf::Median(v), v.size() > 1 ? std::sqrt(squares / (n - 1)) : 0};
                };
                const Aggregates wall = aggregates(usPerStep), cpuTime = aggregates(cpuPerStep);
                for (auto [aggregate, value, cpuValue] :
                     {std::tuple{"mean", wall.mean, cpuTime.mean}, std::tuple{"median", wall.median, cpuTime.median},
                      std::tuple{"stddev", wall.stddev, cpuTime.stddev}}) {
                    json r = row(name + "_" + aggregate, "aggregate", value, cpuValue, usPerStep.size());
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
    // Several sources are one side, their runs pooled; on the CPU clock too, where every source has it.
    perf::Side side, cpu;
    bool everyCpu = true;
    auto pool = [](perf::Side& into, perf::Side&& one) {
        if (into.label.empty()) {
            into = std::move(one);
            return;
        }
        into.label += " " + one.label;
        for (auto& [scene, backends] : one.runs)
            for (auto& [backend, stages] : backends)
                for (auto& [stage, runs] : stages) {
                    auto& to = into.runs[scene][backend][stage];
                    to.insert(to.end(), runs.begin(), runs.end());
                }
    };
    for (const std::string& source : a.positional) {
        if (source.empty()) return Usage("perf export: SOURCE must not be empty");
        auto one = perf::LoadSide(source);
        if (!one) {
            std::fprintf(stderr, "%s\n", one.error().message.c_str());
            return kExitBadScene;
        }
        pool(side, std::move(*one));
        if (auto onCpu = perf::LoadSide(source, perf::Clock::Cpu); onCpu && everyCpu)
            pool(cpu, std::move(*onCpu));
        else
            everyCpu = false;
    }
    if (!everyCpu) cpu = perf::Side{};
    return WriteJsonFile(a.Value("--gbench"), GbenchJson(side, cpu)) ? kExitOk : kExitFailed;
}

}  // namespace cb::perf_command
