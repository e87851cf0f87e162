#include "harness/perf/Compare.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "harness/perf/History.h"
#include "harness/report/InputFormats.h"

namespace cb::perf {
namespace {

using nlohmann::json;

Status AddRecord(Side& side, const json& record) {
    try {
        for (const auto& [scene, backends] : record.at("results").items())
            for (const auto& [backend, stages] : backends.items())
                for (const auto& [stage, entry] : stages.items()) {
                    auto& samples = side.samplesMs[scene][backend][stage];
                    for (const json& v : entry.at("samples_ms")) samples.push_back(v.get<double>());
                }
        if (record.contains("failures"))
            for (const auto& [scene, backends] : record["failures"].items())
                for (const auto& [backend, why] : backends.items())
                    side.failures[scene][backend] = why.get<std::string>();
        if (record.contains("instructions")) CB_TRY(AddInstructions(side, record));
        side.provenance = record.value("provenance", json::object());
        side.date = record.value("time", "");
    } catch (const json::exception& e) {
        return MakeError(side.label + ": not a valid " + kRecordFormat + " record: " + e.what());
    }
    return {};
}

}  // namespace

Status AddResults(Side& side, const json& results) {
    if (!results.is_object() || results.value("format", json()) != "cloudbench-results/1")
        return MakeError(side.label + ": not a results.json (format cloudbench-results/1)");
    try {
        const std::string scene = results.at("scene").at("name").get<std::string>();
        for (const auto& [backend, entry] : results.at("backends").items()) {
            const std::string status = entry.value("status", "");
            if (status == "unavailable" || status == "unsupported") continue;  // not measured here: absent
            if (status != "ok") {
                side.failures[scene][backend] =
                    status + (entry.contains("error") ? ": " + entry.value("error", "") : "");
            }
            if (!entry.contains("stages")) continue;
            for (const auto& [stage, stats] : entry["stages"].items()) {
                auto& samples = side.samplesMs[scene][backend][stage];
                for (const json& v : stats.at("samples_ms")) samples.push_back(v.get<double>());
            }
        }
        if (side.provenance.empty() && results.contains("provenance")) {
            side.provenance = results["provenance"];
            side.date = side.provenance.value("date", "");
        }
    } catch (const json::exception& e) {
        return MakeError(side.label + ": not a valid results.json: " + e.what());
    }
    return {};
}

Status AddInstructions(Side& side, const json& doc) {
    try {
        for (const auto& [scene, backends] : doc.at("instructions").items())
            for (const auto& [backend, stages] : backends.items())
                for (const auto& [stage, count] : stages.items())
                    side.instructions[scene][backend][stage] = count.get<double>();
    } catch (const json::exception& e) {
        return MakeError(side.label + ": \"instructions\" must map scene, backend and stage to a count: " + e.what());
    }
    return {};
}

Result<Side> LoadSide(const std::string& spec) {
    // "FILE@SELECTOR" names a record of a history; a file whose own name holds '@' is taken whole.
    std::string path = spec, selector;
    bool selected = false;
    struct stat st {};
    if (const size_t at = spec.rfind('@'); at != std::string::npos && at > 0 && ::stat(spec.c_str(), &st) != 0) {
        path = spec.substr(0, at);
        selector = spec.substr(at + 1);
        selected = true;
    }
    Side side;
    side.label = spec;
    // A record alone is read as a history of one (input::ReadDocumentOrHistory).
    static constexpr input::Format kSides[] = {input::Format::Results, input::Format::Count,
                                               input::Format::Instructions};
    auto read = input::ReadDocumentOrHistory(path, kSides);
    if (!read) return std::unexpected(read.error());
    if (auto* one = std::get_if<input::Document>(&*read)) {
        if (selected) return MakeError(spec + ": '@' selects a record of a history, and " + path + " is not one");
        const json& doc = one->doc;
        switch (one->format) {
            case input::Format::Results:
                CB_TRY(AddResults(side, doc));
                break;
            default:  // a count output or an instruction file
                CB_TRY(AddInstructions(side, doc));
                side.provenance = doc.value("provenance", json::object());
                side.date = side.provenance.value("date", "");
                break;
        }
        return side;
    }
    auto& history = std::get<input::History>(*read);
    input::PrintWarnings(history);
    auto record = SelectRecord(history.records, path, selected ? selector : "-1");
    if (!record) return std::unexpected(record.error());
    side.label = path + "@" + (*record)->record.value("id", "-1");
    CB_TRY(AddRecord(side, (*record)->record));
    return side;
}

json RecordSections(const Side& side) {
    json results = json::object(), failures = json::object(), instructions = json::object();
    for (const auto& [scene, backends] : side.samplesMs)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, samples] : stages)
                results[scene][backend][stage] = {{"samples_ms", samples}, {"median_ms", Median(samples)}};
    for (const auto& [scene, backends] : side.failures)
        for (const auto& [backend, why] : backends) failures[scene][backend] = why;
    for (const auto& [scene, backends] : side.instructions)
        for (const auto& [backend, stages] : backends)
            for (const auto& [stage, count] : stages) instructions[scene][backend][stage] = count;
    return {{"results", results}, {"failures", failures}, {"instructions", instructions}};
}

size_t CompareOutcome::Regressions() const {
    return size_t(std::count_if(rows.begin(), rows.end(), [](const Comparison& c) { return c.regression; }));
}

namespace {

// Why `side` has no samples for scene/backend, or "" when it has them.
std::string Failure(const Side& side, const std::string& scene, const std::string& backend) {
    if (auto s = side.failures.find(scene); s != side.failures.end())
        if (auto b = s->second.find(backend); b != s->second.end()) return b->second;
    return "";
}

template <typename T>
const T* Find(const ByStage<T>& map, const std::string& scene, const std::string& backend, const std::string& stage) {
    auto s = map.find(scene);
    if (s == map.end()) return nullptr;
    auto b = s->second.find(backend);
    if (b == s->second.end()) return nullptr;
    auto t = b->second.find(stage);
    return t == b->second.end() ? nullptr : &t->second;
}

// Every key of either map, in order.
template <typename T>
std::vector<std::array<std::string, 3>> Keys(const ByStage<T>& a, const ByStage<T>& b) {
    std::vector<std::array<std::string, 3>> keys;
    for (const ByStage<T>* map : {&a, &b})
        for (const auto& [scene, backends] : *map)
            for (const auto& [backend, stages] : backends)
                for (const auto& [stage, unused] : stages) keys.push_back({scene, backend, stage});
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    return keys;
}

}  // namespace

double ThresholdOf(const CompareSettings& s, const std::string& backend) {
    auto own = s.backendThreshold.find(backend);
    const double threshold = own == s.backendThreshold.end() ? s.threshold : own->second;
    return s.interleaved ? threshold : std::max(threshold, s.separateThreshold);
}

CompareOutcome Compare(const Side& base, const Side& head, const CompareSettings& s) {
    CompareOutcome out;
    out.separate = !s.interleaved;
    out.threshold = ThresholdOf(s, "");
    std::vector<size_t> tested;  // rows with a test, for Holm's correction
    for (const auto& [scene, backend, stage] : Keys(base.samplesMs, head.samplesMs)) {
        Comparison c;
        c.scene = scene, c.backend = backend, c.stage = stage, c.metric = "time";
        const std::vector<double>* b = Find(base.samplesMs, scene, backend, stage);
        const std::vector<double>* h = Find(head.samplesMs, scene, backend, stage);
        if (b) c.baseCount = b->size(), c.baseMedian = Median(*b);
        if (h) c.headCount = h->size(), c.headMedian = Median(*h);
        if (c.baseCount && c.headCount) c.ratio = c.headMedian / c.baseMedian;
        const std::string headFailure = Failure(head, scene, backend);
        if (!headFailure.empty() || !c.headCount) {
            c.mark = 'x';
            c.note = headFailure.empty() ? "no samples in HEAD" : "HEAD: " + headFailure;
        } else if (!c.baseCount) {
            c.mark = '!';
            c.note = "new: no samples in BASE";
        } else if (c.baseCount < s.minSamples || c.headCount < s.minSamples) {
            c.note = "too few samples to test (at least " + std::to_string(s.minSamples) + " a side)";
        } else {
            c.interval = BootstrapRatioOfMedians(*b, *h, s.confidence, s.resamples, s.seed);
            c.pSlower = MannWhitneyGreater(*h, *b).p;
            c.pFaster = MannWhitneyGreater(*b, *h).p;
            tested.push_back(out.rows.size());
        }
        out.rows.push_back(c);
    }
    std::vector<double> slower, faster;
    for (size_t i : tested) slower.push_back(out.rows[i].pSlower), faster.push_back(out.rows[i].pFaster);
    const std::vector<double> slowerHolm = HolmAdjusted(slower), fasterHolm = HolmAdjusted(faster);
    for (size_t n = 0; n < tested.size(); ++n) {
        Comparison& c = out.rows[tested[n]];
        c.pSlowerHolm = slowerHolm[n];
        c.pFasterHolm = fasterHolm[n];
        const bool slowerSignificant = c.pSlowerHolm < s.alpha, fasterSignificant = c.pFasterHolm < s.alpha;
        const double difference = c.headMedian - c.baseMedian;
        c.threshold = ThresholdOf(s, c.backend);
        if (slowerSignificant && c.ratio > c.threshold && difference > s.floorMs) {
            c.mark = '+';
            c.regression = true;
            c.note = "regression";
        } else if (fasterSignificant && c.ratio < 1 / c.threshold && -difference > s.floorMs) {
            c.mark = '-';
            c.note = "improvement";
        } else if (slowerSignificant || fasterSignificant) {
            c.note = std::abs(difference) <= s.floorMs ? "significant, under the floor"
                                                       : "significant, within the threshold";
        } else {
            c.note = "not significant";
        }
    }
    // Instruction counts are exact: a change beyond the threshold is a change, no test needed. A side
    // without any counts (no `count` run) is not compared.
    if (base.instructions.empty() || head.instructions.empty()) {
        out.headFailed =
            std::any_of(out.rows.begin(), out.rows.end(), [](const Comparison& c) { return c.mark == 'x'; });
        return out;
    }
    for (const auto& [scene, backend, stage] : Keys(base.instructions, head.instructions)) {
        Comparison c;
        c.scene = scene, c.backend = backend, c.stage = stage, c.metric = "instructions";
        const double* b = Find(base.instructions, scene, backend, stage);
        const double* h = Find(head.instructions, scene, backend, stage);
        if (b) c.baseCount = 1, c.baseMedian = *b;
        if (h) c.headCount = 1, c.headMedian = *h;
        if (!h) {
            c.mark = 'x';
            c.note = "no count in HEAD";
        } else if (!b) {
            c.mark = '!';
            c.note = "new: no count in BASE";
        } else {
            c.ratio = *b > 0 ? *h / *b : (*h > 0 ? INFINITY : 1.0);
            c.threshold = 1 + s.instructionThreshold;
            if (c.ratio > 1 + s.instructionThreshold) {
                c.mark = '+';
                c.regression = true;
                c.note = "regression";
            } else if (c.ratio < 1 / (1 + s.instructionThreshold)) {
                c.mark = '-';
                c.note = "improvement";
            } else {
                c.note = c.ratio == 1 ? "same count" : "within the threshold";
            }
        }
        out.rows.push_back(c);
    }
    out.headFailed = std::any_of(out.rows.begin(), out.rows.end(), [](const Comparison& c) { return c.mark == 'x'; });
    return out;
}

}  // namespace cb::perf
