#include "harness/run/RunTransfer.h"

#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "harness/platform/TransferJson.h"

namespace cb::transfer {
namespace {

// A frame's counters, named by its renderer's list.
json CountersJson(const FrameRecord& f) {
    json out = json::object();
    const std::span<const FrameCounterField> fields = Describe(f.renderer).renderer->counters;
    for (size_t i = 0; i < fields.size(); ++i) out[std::string(fields[i].name)] = f.counters[i];
    return out;
}
void CountersFromJson(const json& j, FrameRecord& f) {
    const std::span<const FrameCounterField> fields = Describe(f.renderer).renderer->counters;
    for (size_t i = 0; i < fields.size(); ++i) f.counters[i] = j.at(std::string(fields[i].name)).get<uint64_t>();
}
// Where a frame keeps its counters: in itself, or under its renderer's key.
std::string_view RecordKey(const FrameRecord& f) { return Describe(f.renderer).renderer->recordKey; }

}  // namespace

json ToJson(const StepRecord& r) {
    json stageMs = json::array(), hostMs = json::array(), cpuMs = json::array(), deviceMs = json::array(),
         frames = json::array(), skipped = json::array();
    for (size_t s = 0; s < kStageCount; ++s) {
        stageMs.push_back(Optional(r.stageMs[s]));
        hostMs.push_back(Optional(r.hostMs[s]));
        cpuMs.push_back(Optional(r.cpuMs[s]));
        deviceMs.push_back(Optional(r.deviceMs[s]));
        skipped.push_back(r.skippedUnchanged[s]);
    }
    for (const FrameRecord& f : r.frames) {
        frames.push_back({{"renderer", StageName(f.renderer)},
                          {"camera", f.camera},
                          {"frame", f.frame},
                          {"alpha", D(f.alpha)},
                          {"ms", D(f.ms)},
                          {"pipelined", f.pipelined},
                          {"device_ms", Optional(f.deviceMs)}});
        if (RecordKey(f).empty())
            frames.back().update(CountersJson(f));
        else
            frames.back()[std::string(RecordKey(f))] = CountersJson(f);
    }
    json frameMs = json::array();
    for (double ms : r.frameMs) frameMs.push_back(D(ms));
    return {{"step", r.step},
            {"timing", TimingModeName(r.timing)},
            {"stage_ms", stageMs},
            {"host_ms", hostMs},
            {"cpu_ms", cpuMs},
            {"submissions", r.submissions},
            {"host_waits", r.hostWaits},
            {"batches", r.batches},
            {"device_ms", deviceMs},
            {"ellipsoid_update_ms", D(r.ellipsoidUpdateMs)},
            {"covered_columns", Optional(r.coveredColumns)},
            {"skipped_unchanged", skipped},
            {"frames_rendered", r.framesRendered},
            {"step_ms", D(r.stepMs)},
            {"frame_ms", frameMs},
            {"frame_work", r.frameWork},
            {"frames", frames}};
}

StepRecord StepFromJson(const json& j) {
    StepRecord r;
    r.step = j.at("step").get<uint32_t>();
    for (size_t s = 0; s < kStageCount; ++s) {
        r.stageMs[s] = OptionalFrom<double>(j.at("stage_ms").at(s));
        r.deviceMs[s] = OptionalFrom<double>(j.at("device_ms").at(s));
        r.hostMs[s] = OptionalFrom<double>(j.at("host_ms").at(s));
        r.cpuMs[s] = OptionalFrom<double>(j.at("cpu_ms").at(s));
    }
    r.timing = j.at("timing").get<std::string>() == "pipelined" ? TimingMode::Pipelined : TimingMode::Synchronized;
    r.submissions = j.at("submissions").get<uint64_t>();
    r.hostWaits = j.at("host_waits").get<uint64_t>();
    r.batches = j.at("batches").get<uint32_t>();
    r.ellipsoidUpdateMs = FromD(j.at("ellipsoid_update_ms"));
    r.coveredColumns = OptionalFrom<uint32_t>(j.at("covered_columns"));
    for (size_t s = 0; s < kStageCount; ++s) r.skippedUnchanged[s] = j.at("skipped_unchanged").at(s).get<bool>();
    r.framesRendered = j.at("frames_rendered").get<uint32_t>();
    r.stepMs = FromD(j.at("step_ms"));
    for (const json& ms : j.at("frame_ms")) r.frameMs.push_back(FromD(ms));
    r.frameWork = j.at("frame_work").get<std::vector<std::string>>();
    for (const json& f : j.at("frames")) {
        FrameRecord frame;
        const std::string renderer = f.at("renderer").get<std::string>();
        const std::optional<Stage> stage = ParseStage(renderer);
        if (!stage || !Describe(*stage).renderer) throw std::runtime_error("a frame of \"" + renderer + "\", not a renderer");
        frame.renderer = *stage;
        frame.camera = f.at("camera").get<std::string>();
        frame.frame = f.at("frame").get<uint32_t>();
        frame.alpha = float(FromD(f.at("alpha")));
        frame.ms = FromD(f.at("ms"));
        frame.pipelined = f.at("pipelined").get<bool>();
        frame.deviceMs = OptionalFrom<double>(f.at("device_ms"));
        CountersFromJson(RecordKey(frame).empty() ? f : f.at(std::string(RecordKey(frame))), frame);
        r.frames.push_back(std::move(frame));
    }
    return r;
}

json ToJson(const BackendProvenance& b) {
    return {{"name", b.name}, {"status", b.status}, {"device", b.device}, {"reason", b.reason}};
}
BackendProvenance ProvenanceFromJson(const json& j) {
    return {j.at("name").get<std::string>(), j.at("status").get<std::string>(), j.at("device").get<std::string>(),
            j.at("reason").get<std::string>()};
}

}  // namespace cb::transfer
