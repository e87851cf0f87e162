#include "harness/perf/CallgrindDump.h"

#include <charconv>
#include <set>
#include <tuple>

namespace cb {
namespace {

constexpr std::string_view kClientRequest = "Client Request: ";

std::string_view Trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
    return s;
}

std::vector<std::string_view> Words(std::string_view s) {
    std::vector<std::string_view> words;
    while (true) {
        s = Trim(s);
        if (s.empty()) return words;
        const size_t end = std::min(s.find_first_of(" \t"), s.size());
        words.push_back(s.substr(0, end));
        s.remove_prefix(end);
    }
}

template <typename T>
std::optional<T> ParseUnsigned(std::string_view s) {
    T value{};
    auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
    return value;
}

// A part being read: its trigger, the position of Ir among its events, its total.
struct OpenPart {
    std::string trigger;
    std::optional<size_t> irColumn;
    std::optional<uint64_t> totals, summary;
    size_t line = 0;  // where it began
};

}  // namespace

Result<std::vector<CallgrindPart>> ParseCallgrindDump(std::string_view text) {
    std::vector<CallgrindPart> parts;
    std::optional<OpenPart> part;
    auto where = [](size_t line) { return "line " + std::to_string(line) + ": "; };
    auto close = [&]() -> Status {
        if (!part) return {};
        if (!part->irColumn) return MakeError(where(part->line) + "part has no \"events:\" line naming Ir");
        const std::optional<uint64_t> total = part->totals ? part->totals : part->summary;
        if (!total) return MakeError(where(part->line) + "part has no \"totals:\" or \"summary:\" line");
        parts.push_back({part->trigger, *total});
        part.reset();
        return {};
    };
    // The Ir column of a "totals:"/"summary:" line.
    auto readTotal = [&](std::string_view values, size_t line) -> Result<uint64_t> {
        if (!part->irColumn) return MakeError(where(line) + "a total before the \"events:\" line");
        const std::vector<std::string_view> words = Words(values);
        if (*part->irColumn >= words.size()) return MakeError(where(line) + "no Ir value in the total");
        auto value = ParseUnsigned<uint64_t>(words[*part->irColumn]);
        if (!value) return MakeError(where(line) + "not a count: '" + std::string(words[*part->irColumn]) + "'");
        return *value;
    };
    size_t lineNumber = 0;
    for (size_t start = 0; start < text.size();) {
        const size_t end = std::min(text.find('\n', start), text.size());
        const std::string_view line = Trim(text.substr(start, end - start));
        start = end + 1;
        ++lineNumber;
        // A part begins at "part: N"; a file without that line is one part.
        if (line.starts_with("part:")) {
            CB_TRY(close());
            part.emplace();
            part->line = lineNumber;
            continue;
        }
        const bool partLine = line.starts_with("desc:") || line.starts_with("events:") ||
                              line.starts_with("totals:") || line.starts_with("summary:");
        if (!part && partLine) {
            part.emplace();
            part->line = lineNumber;
        }
        if (!part) continue;
        if (line.starts_with("desc: Trigger:")) {
            part->trigger = std::string(Trim(line.substr(std::string_view("desc: Trigger:").size())));
        } else if (line.starts_with("events:")) {
            const std::vector<std::string_view> events = Words(line.substr(7));
            for (size_t n = 0; n < events.size(); ++n)
                if (events[n] == "Ir") part->irColumn = n;
            if (!part->irColumn) return MakeError(where(lineNumber) + "the events do not include Ir");
        } else if (line.starts_with("totals:")) {
            auto value = readTotal(line.substr(7), lineNumber);
            if (!value) return std::unexpected(value.error());
            part->totals = *value;
        } else if (line.starts_with("summary:")) {
            auto value = readTotal(line.substr(8), lineNumber);
            if (!value) return std::unexpected(value.error());
            part->summary = *value;
        }
    }
    CB_TRY(close());
    if (parts.empty()) return MakeError("no dump in the file");
    return parts;
}

std::optional<StageCountName> ParseStageCountName(std::string_view name) {
    StageCountName out;
    // The camera is the rest of the name: it may hold spaces.
    if (const size_t camera = name.find(" camera="); camera != std::string_view::npos) {
        out.camera = std::string(name.substr(camera + 8));
        if (out.camera.empty()) return std::nullopt;
        name = name.substr(0, camera);
    }
    const std::vector<std::string_view> words = Words(name);
    if (words.size() != 3 || !words[0].starts_with("stage=") || !words[1].starts_with("backend=") ||
        !words[2].starts_with("step="))
        return std::nullopt;
    out.stage = std::string(words[0].substr(6));
    out.backend = std::string(words[1].substr(8));
    const auto step = ParseUnsigned<uint32_t>(words[2].substr(5));
    if (out.stage.empty() || out.backend.empty() || !step) return std::nullopt;
    out.step = *step;
    return out;
}

Result<StageCounts> CountStageCalls(const std::vector<CallgrindPart>& parts) {
    StageCounts counts;
    std::set<std::tuple<std::string, std::string, uint32_t, std::string>> seen;
    for (const CallgrindPart& part : parts) {
        if (!part.trigger.starts_with(kClientRequest)) continue;
        const std::string_view name = std::string_view(part.trigger).substr(kClientRequest.size());
        const std::optional<StageCountName> call = ParseStageCountName(name);
        if (!call) return MakeError("a dump named '" + std::string(name) + "' is not a stage call's");
        if (!seen.insert({call->backend, call->stage, call->step, call->camera}).second)
            return MakeError("the stage call '" + std::string(name) + "' was counted twice");
        counts[call->backend][call->stage][call->step] += part.instructions;
    }
    return counts;
}

}  // namespace cb
