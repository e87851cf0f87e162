// `cloudbench perf export` (docs/cli.md, "perf"): writes a results file, a
// count output or a history record as Google Benchmark's JSON for compare.py.
#include <cstdio>

#include "harness/commands/PerfCommon.h"

namespace cb::perf_command {
namespace {

// Google Benchmark's JSON (what --benchmark_format=json writes): one
// "iteration" entry per step sample, named scene/backend/stage, so that
// compare.py can run its U test over the samples. cpu_time repeats the wall
// time: cloudbench measures no CPU time.
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
    for (const auto& [scene, backends] : side.samplesMs)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, samples] : stages) {
                const std::string name = scene + "/" + backend + "/" + stage;
                for (size_t i = 0; i < samples.size(); ++i)
                    doc["benchmarks"].push_back({{"name", name},
                                                 {"family_index", 0},
                                                 {"per_family_instance_index", 0},
                                                 {"run_name", name},
                                                 {"run_type", "iteration"},
                                                 {"repetitions", samples.size()},
                                                 {"repetition_index", i},
                                                 {"threads", 1},
                                                 {"iterations", 1},
                                                 {"real_time", samples[i]},
                                                 {"cpu_time", samples[i]},
                                                 {"time_unit", "ms"}});
            }
    return doc;
}

}  // namespace

int Export(const std::vector<std::string>& args) {
    ParsedArgs a;
    if (auto m = Parse(args, {"--gbench"}, {}, a)) return Usage(*m);
    if (!a.Has("--gbench")) return Usage("perf export needs --gbench OUT");
    if (a.positional.size() != 1 || a.positional[0].empty()) return Usage("perf export needs one SOURCE");
    auto side = perf::LoadSide(a.positional[0]);
    if (!side) {
        std::fprintf(stderr, "%s\n", side.error().message.c_str());
        return kExitBadScene;
    }
    return WriteJsonFile(a.Value("--gbench"), GbenchJson(*side)) ? kExitOk : kExitFailed;
}

}  // namespace cb::perf_command
