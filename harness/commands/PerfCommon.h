// What the `cloudbench perf` subcommands share (harness/commands/PerfCommand.cpp
// dispatches to them, one file each: PerfRecord.cpp, PerfCompare.cpp,
// PerfHistory.cpp, PerfExport.cpp): the usage message, option parsing, number
// options, JSON output, a temporary folder and one child `cloudbench run`.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "harness/perf/Compare.h"
#include "harness/platform/Command.h"

namespace cb::perf_command {

using nlohmann::json;

// Prints `message` and perf's help to stderr; returns kExitUsage (PerfCommand.cpp).
int Usage(const std::string& message);

// The subcommands; args[0] is the subcommand's name. Each returns perf's exit code.
int Record(const std::vector<std::string>& args, const CommonOptions& options);
int ComparePerf(const std::vector<std::string>& args);
int History(const std::vector<std::string>& args);
int Export(const std::vector<std::string>& args);

// Options of one subcommand: those taking a value, repeatable, and flags.
struct ParsedArgs {
    std::vector<std::string> positional;
    std::map<std::string, std::vector<std::string>> values;
    std::set<std::string> flags;

    std::string Value(const std::string& name, const std::string& fallback = "") const {
        auto it = values.find(name);
        return it == values.end() ? fallback : it->second.back();
    }
    bool Has(const std::string& name) const { return values.count(name) || flags.count(name); }
};

// Parses args[1..] into `out`; the usage message on an unknown option or a missing value.
std::optional<std::string> Parse(const std::vector<std::string>& args, const std::set<std::string>& valueOptions,
                                 const std::set<std::string>& flagOptions, ParsedArgs& out);

// `v` printed with `format`; "" for NaN.
std::string Num(const char* format, double v);

// A number option in [low, high]; the usage message when it is not one:
// "NAME: needs a number in [LOW, HIGH], got 'TEXT'". `value` is left as it is when the option is absent.
std::optional<std::string> NumberOption(const ParsedArgs& a, const std::string& name, double low, double high,
                                        double& value);
// The same for a count: "NAME: needs a whole number in [LOW, HIGH], got 'TEXT'" (ParseWholeNumber).
std::optional<std::string> WholeNumberOption(const ParsedArgs& a, const std::string& name, long long low,
                                             long long high, long long& value);

// Writes `doc` to `path` whole (Session::WriteText: a temporary file in the same
// folder, renamed; never through a link); on failure prints
// "PATH: cannot write: <strerror>" and returns false.
bool WriteJsonFile(const std::string& path, const json& doc);

// A temporary folder for runs' outputs, removed when this goes out of scope;
// none (an empty path) unless `create`.
struct TemporaryFolder {
    explicit TemporaryFolder(bool create = true);
    ~TemporaryFolder();
    std::string path;
};

// One `cloudbench run` of `scene` by `binary` into `out`, its results added to
// `side` as one run measured in `round` (-1 outside an interleave). Returns the
// exit code the perf command should end with at once (a bad scene or command
// line), or nullopt to go on; `failed` is set when the run failed (it exited
// other than 0, or wrote no valid results.json), `exitCode` (when given)
// receives the run's own exit code and `compared` (when given) whether its
// results were added. `setEnv` ("NAME=VALUE" each) is set in the run's environment (perf::RunChild).
std::optional<int> RunInto(const std::string& binary, const std::string& scene, const std::vector<std::string>& extra,
                           const std::string& out, const std::string& log, perf::Side& side, bool& failed,
                           int round = -1, int* exitCode = nullptr, bool* compared = nullptr,
                           const std::vector<std::string>& setEnv = {});

}  // namespace cb::perf_command
