// The plumbing the `cloudbench perf` subcommands share (harness/commands/PerfCommon.h).
#include "harness/commands/PerfCommon.h"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/base/NamedValues.h"
#include "core/base/ShownText.h"
#include "harness/perf/Spawn.h"
#include "harness/report/InputFormats.h"
#include "harness/run/Session.h"

namespace cb::perf_command {

namespace fs = std::filesystem;

std::optional<std::string> Parse(const std::vector<std::string>& args, const std::set<std::string>& valueOptions,
                                 const std::set<std::string>& flagOptions, ParsedArgs& out) {
    for (size_t n = 1; n < args.size(); ++n) {
        const std::string& arg = args[n];
        if (valueOptions.count(arg)) {
            if (n + 1 >= args.size()) return arg + " needs a value";
            if (args[n + 1].empty()) return arg + ": must not be empty";
            out.values[arg].push_back(args[++n]);
        } else if (flagOptions.count(arg)) {
            out.flags.insert(arg);
        } else if (arg.size() > 1 && arg[0] == '-' && !std::isdigit(static_cast<unsigned char>(arg[1]))) {
            std::vector<std::string_view> known(valueOptions.begin(), valueOptions.end());
            known.insert(known.end(), flagOptions.begin(), flagOptions.end());
            const std::string_view best = ClosestName(arg, known);
            return "unknown option '" + ShownArgument(arg) + "' for perf " + args[0] +
                   (best.empty() ? "" : "; did you mean '" + std::string(best) + "'?");
        } else {
            out.positional.push_back(arg);
        }
    }
    return std::nullopt;
}

std::string Num(const char* format, double v) {
    if (std::isnan(v)) return "";
    char text[64];
    std::snprintf(text, sizeof text, format, v);
    return text;
}

std::optional<std::string> NumberOption(const ParsedArgs& a, const std::string& name, double low, double high,
                                        double& value) {
    if (!a.values.count(name)) return std::nullopt;
    const std::string text = a.Value(name);
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    // A whole bound in full ("1000000", as docs/cli.md gives it), any other in %g ("1e-12").
    auto bound = [](double b) { return Num(b == std::floor(b) && std::fabs(b) < 1e15 ? "%.0f" : "%g", b); };
    if (end == text.c_str() || *end != '\0' || !(v >= low && v <= high))
        return name + ": needs a number in [" + bound(low) + ", " + bound(high) + "], got '" + ShownArgument(text) +
               "'";
    value = v;
    return std::nullopt;
}

std::optional<std::string> WholeNumberOption(const ParsedArgs& a, const std::string& name, long long low,
                                             long long high, long long& value) {
    if (!a.values.count(name)) return std::nullopt;
    return ParseWholeNumber(name, a.Value(name).c_str(), low, high, value);
}

bool WriteJsonFile(const std::string& path, const json& doc) {
    if (Status s = Session::WriteText(path, doc.dump(1) + "\n"); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return false;
    }
    return true;
}

TemporaryFolder::TemporaryFolder(bool create) {
    if (!create) return;
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/cloudbench-perf-XXXXXX";
    if (char* made = ::mkdtemp(pattern.data())) path = made;
}

TemporaryFolder::~TemporaryFolder() {
    std::error_code ec;
    if (!path.empty()) fs::remove_all(path, ec);
}

std::optional<int> RunInto(const std::string& binary, const std::string& scene, const std::vector<std::string>& extra,
                           const std::string& out, const std::string& log, perf::Side& side, bool& failed, int round,
                           int* exitCode, bool* compared, const std::vector<std::string>& setEnv) {
    std::vector<std::string> argv = {binary, "run", scene, "--out", out, "--quiet"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto rc = perf::RunChild(argv, log, setEnv);
    if (!rc) {
        std::fprintf(stderr, "%s\n", rc.error().message.c_str());
        return kExitFailed;
    }
    if (exitCode) *exitCode = *rc;
    if (*rc == kExitUsage || *rc == kExitBadScene) {
        std::fprintf(stderr, "perf: %s run %s exited %d (see its message above)\n", binary.c_str(), scene.c_str(), *rc);
        return *rc;
    }
    static constexpr input::Format kResults[] = {input::Format::Results};
    auto results = input::ReadCloudbenchFile(out + "/results.json", kResults);
    if (!results) {
        std::fprintf(stderr, "perf: %s run %s exited %d and wrote no valid results.json: %s\n", binary.c_str(),
                     scene.c_str(), *rc, results.error().message.c_str());
        failed = true;
        return std::nullopt;
    }
    if (*rc != kExitOk) {
        std::fprintf(stderr, "perf: %s run %s exited %d\n", binary.c_str(), scene.c_str(), *rc);
        failed = true;
    }
    if (Status s = perf::AddResults(side, results->doc, round); !s) {
        std::fprintf(stderr, "%s\n", s.error().message.c_str());
        return kExitFailed;
    }
    if (compared) *compared = true;
    return std::nullopt;
}

}  // namespace cb::perf_command
