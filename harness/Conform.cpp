#include "harness/Conform.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "core/SceneNames.h"
#include "core/StageDescriptors.h"
#include "harness/Command.h"
#include "harness/Report.h"
#include "harness/Simulation.h"
#include "harness/StageCall.h"

namespace cb {
namespace {

template <typename T>
Result<std::vector<T>> Read(Backend& backend, const Buffer& buffer) {
    return Download<T>(backend, buffer);
}

template <typename T>
Result<std::unique_ptr<Buffer>> Filled(Backend& backend, BufferFormat format, Extent3 extent,
                                       const std::vector<T>& data) {
    auto buffer = backend.CreateBuffer(format, extent);
    if (!buffer) return std::unexpected(buffer.error());
    CB_TRY(backend.Upload(**buffer, std::as_bytes(std::span(data))));
    return std::move(*buffer);
}

std::string Where(const Extent3& e, size_t v) {
    std::ostringstream s;
    s << "(" << v % e.nx << ", " << (v / e.nx) % e.ny << ", " << v / (size_t(e.nx) * e.ny) << ")";
    return s.str();
}

// A backend that could not run its stages, or whose process died (ChildFailure::status).
bool IsBrokenStatus(const std::string& status) {
    return status == "failed" || status == "crashed" || status == "timed out" || status == "out of memory";
}

// The test-only switch CLOUDBENCH_TEST_CONFORM_MISMATCH=<backend>:<row stage>[:<attempts>]
// (harness/Conform.h): whether this backend's output of this row is to be perturbed on this attempt.
bool ConformTestMismatch(const std::string& backend, const std::string& stage, uint32_t attempt) {
    const char* value = std::getenv("CLOUDBENCH_TEST_CONFORM_MISMATCH");
    if (!value || !*value) return false;
    const std::string text(value);
    const size_t colon = text.find(':');
    if (colon == std::string::npos || text.substr(0, colon) != backend) return false;
    const std::string rest = text.substr(colon + 1);
    const size_t second = rest.find(':');
    if (rest.substr(0, second) != stage) return false;
    if (second == std::string::npos) return true;
    return attempt < uint32_t(std::strtoul(rest.c_str() + second + 1, nullptr, 10));
}

// Accumulates the worst result of one stage x backend over the steps.
class Tally {
  public:
    std::string differenceDir;  // where renderer rows write their worst frame's difference image; "" = nowhere
    uint32_t attempt = 0;       // 0 first, 1.. for --flake-reruns (the test-only mismatch switch)
    ConformRow& Row(const std::string& stage, const std::string& backend, const std::string& rule, double tolerance) {
        auto key = stage + "/" + backend;
        auto [it, inserted] = mRows.try_emplace(key);
        if (inserted) {
            it->second.stage = stage;
            it->second.backend = backend;
            it->second.rule = rule;
            it->second.tolerance = tolerance;
            mOrder.push_back(key);
        }
        return it->second;
    }
    // An exact comparison: every element equal.
    template <typename T>
    void Exact(const std::string& stage, const std::string& backend, uint32_t step, const Extent3& e,
               const std::vector<T>& ref, const std::vector<T>& got) {
        ConformRow& row = Row(stage, backend, "bit-exact", 0);
        size_t differ = 0, first = 0;
        for (size_t v = 0; v < ref.size(); ++v)
            if (std::memcmp(&ref[v], &got[v], sizeof(T)) != 0 && differ++ == 0) first = v;
        if (double(differ) > row.worst) {
            row.worst = double(differ);
            std::ostringstream d;
            d << differ << " differ at step " << step << ", first " << Where(e, first) << ": cpu " << +ref[first]
              << ", " << backend << " " << +got[first];
            row.detail = d.str();
        }
        if (differ) row.status = "fail";
    }
    // |a - b| <= tolerance everywhere.
    void Within(const std::string& stage, const std::string& backend, uint32_t step, const Extent3& e,
                const std::vector<float>& ref, const std::vector<float>& got, double tolerance,
                const std::string& rule) {
        ConformRow& row = Row(stage, backend, rule, tolerance);
        double worst = 0;
        size_t at = 0;
        for (size_t v = 0; v < ref.size(); ++v) {
            const double d = std::fabs(double(ref[v]) - double(got[v]));
            if (!(d <= worst)) worst = d, at = v;
        }
        if (!(worst <= row.worst)) {
            row.worst = worst;
            std::ostringstream d;
            d << "step " << step << " at " << Where(e, at) << ": cpu " << ref[at] << ", " << backend << " " << got[at];
            row.detail = d.str();
        }
        if (!(worst <= tolerance)) row.status = "fail";
    }
    std::vector<ConformRow> Rows() const {
        std::vector<ConformRow> out;
        for (const std::string& key : mOrder) out.push_back(mRows.at(key));
        return out;
    }

  private:
    std::map<std::string, ConformRow> mRows;
    std::vector<std::string> mOrder;
};

}  // namespace

namespace {

// A stage of one backend that advances the state (the automaton): its outputs
// are step t+1's, compared after the CPU has stepped.
struct PendingState {
    Stage stage;
    std::string backend;
    Backend* owner;
    std::vector<std::pair<Resource, std::unique_ptr<Buffer>>> outputs;
};

// Compares one output buffer of `stage` with the CPU's by the stage's rule.
Status CompareOutput(Tally& tally, const Scene& scene, Stage stage, const std::string& name, uint32_t t, Backend& cpu,
                     const Buffer& ref, Backend& b, const Buffer& got, const std::string& camera) {
    const StageDescriptor& d = Describe(stage);
    const CompareRule rule = d.rule(scene);
    const std::string stageName(StageName(stage));
    const Extent3 e = ref.Extent();
    if (ref.Format() != BufferFormat::F32) {
        auto r = Read<uint8_t>(cpu, ref);
        auto g = Read<uint8_t>(b, got);
        if (!r || !g) return MakeError(stageName + ": download failed");
        if (!g->empty() && ConformTestMismatch(name, stageName, tally.attempt)) (*g)[0] ^= 1;
        if (rule.kind == CompareRule::Kind::BitExact) {
            tally.Exact(stageName, name, t, e, *r, *g);
            return {};
        }
        // Quantised: |d| <= tolerance everywhere, and at most `share` of the elements differ.
        ConformRow& row = tally.Row(stageName, name, rule.Text(d.symbol), rule.tolerance);
        size_t differ = 0, at = 0;
        int worst = 0;
        for (size_t v = 0; v < r->size(); ++v) {
            const int diff = std::abs(int((*r)[v]) - int((*g)[v]));
            differ += diff != 0;
            if (diff > worst) worst = diff, at = v;
        }
        if (worst > row.worst) {
            row.worst = worst;
            row.detail = "step " + std::to_string(t) + " at " + Where(e, at) + ": cpu " + std::to_string((*r)[at]) +
                         ", " + name + " " + std::to_string((*g)[at]);
        }
        if (worst > rule.tolerance || double(differ) > rule.share * double(r->size())) row.status = "fail";
        return {};
    }
    auto r = Read<float>(cpu, ref);
    auto g = Read<float>(b, got);
    if (!r || !g) return MakeError(stageName + ": download failed");
    if (!g->empty() && ConformTestMismatch(name, stageName, tally.attempt)) (*g)[0] += 1.0f;
    switch (rule.kind) {
        case CompareRule::Kind::BitExact:
            tally.Exact(stageName, name, t, e, *r, *g);
            break;
        case CompareRule::Kind::Absolute:
        case CompareRule::Kind::Quantised:
            tally.Within(stageName, name, t, e, *r, *g, rule.tolerance, rule.Text(d.symbol));
            break;
        case CompareRule::Kind::Codes: {
            // Stored codes as integers, never a float difference against 1/255 (SPEC 6).
            ConformRow& row = tally.Row(stageName, name, rule.Text(d.symbol), rule.tolerance);
            int64_t worst = 0;
            size_t at = 0;
            for (size_t v = 0; v < r->size(); ++v) {
                const int64_t diff = std::llabs(int64_t(StorageCode(rule.storage, (*r)[v])) -
                                                int64_t(StorageCode(rule.storage, (*g)[v])));
                if (diff > worst) worst = diff, at = v;
            }
            if (double(worst) > row.worst) {
                row.worst = double(worst);
                row.detail = "step " + std::to_string(t) + " at " + Where(e, at) + ": cpu code " +
                             std::to_string(StorageCode(rule.storage, (*r)[at])) + ", " + name + " code " +
                             std::to_string(StorageCode(rule.storage, (*g)[at]));
            }
            if (double(worst) > rule.tolerance) row.status = "fail";
            break;
        }
        case CompareRule::Kind::Image: {
            const uint32_t width = e.ny, height = e.nz;  // images are (3, width, height)
            const ImageComparison cmp = CompareImages(*r, *g, width, height, rule);
            ConformRow& row = tally.Row(stageName, name, rule.Text(d.symbol), rule.limit);
            if (!(cmp.maxError <= row.worst)) {
                row.worst = cmp.maxError;
                char detail[256];
                std::snprintf(detail, sizeof detail,
                              "step %u camera %s: worst pixel (%d, %d), %zu pixels over %s, PSNR %.1f dB", t,
                              camera.c_str(), cmp.worstX, cmp.worstY, cmp.pixelsOverTolerance,
                              rule.ToleranceText().c_str(), cmp.psnr);
                row.detail = detail;
                if (!tally.differenceDir.empty()) {
                    const std::string file = "diff-" + stageName + "-" + name + ".exr";
                    if (WriteDifferenceImage(tally.differenceDir + "/" + file, *r, *g, width, height))
                        row.differenceImage = file, row.detail += "; difference image " + file;
                    else
                        row.detail += "; the difference image could not be written";
                }
            }
            if (!cmp.Passes()) row.status = "fail";
            break;
        }
    }
    return {};
}

// A copy of a CPU buffer on backend b, through the canonical layout.
Result<std::unique_ptr<Buffer>> CopyTo(Backend& cpu, const Buffer& from, Backend& b) {
    std::vector<std::byte> data(from.CanonicalBytes());
    CB_TRY(cpu.Download(from, data));
    auto to = b.CreateBuffer(from.Format(), from.Extent());
    if (!to) return std::unexpected(to.error());
    CB_TRY(b.Upload(**to, data));
    return std::move(*to);
}

// Runs `stage` on backend `b` from copies of the CPU simulation's buffers of this step (and of the previous step
// where the stage reads them), into fresh output buffers held in `owned` and named by `io`. A stage that advances
// the state writes into `io.next`; its outputs are moved into a PendingState appended to `pending`.
Status RunOnCopies(Stage stage, const Scene& scene, Backend& b, const Simulation& s, const StageHostInputs& host,
                   std::vector<std::unique_ptr<Buffer>>& owned, StageBuffers& io, Backend* cpuFrom = nullptr,
                   std::vector<PendingState>* pending = nullptr, const std::string& name = "",
                   StageCallRecord* callRecord = nullptr) {
    Backend& cpu = cpuFrom ? *cpuFrom : b;
    const StageDescriptor& d = Describe(stage);
    auto hold = [&](Result<std::unique_ptr<Buffer>> made) -> Result<Buffer*> {
        if (!made) return std::unexpected(made.error());
        owned.push_back(std::move(*made));
        return owned.back().get();
    };
    // Inputs: the CPU's buffers of this step (and the previous one where kept).
    std::vector<Resource> inputs = d.reads;
    inputs.insert(inputs.end(), d.optionalReads.begin(), d.optionalReads.end());
    for (Resource r : inputs) {
        if (!s.Get(r) || !io.current[size_t(r)].empty()) continue;
        auto copy = hold(CopyTo(cpu, *s.Get(r), b));
        if (!copy) return std::unexpected(copy.error());
        io.current[size_t(r)].push_back(*copy);
    }
    if (d.readsPrevious)
        for (Resource r : d.readsPrevious(scene)) {
            if (!s.Previous(r)) continue;
            auto copy = hold(CopyTo(cpu, *s.Previous(r), b));
            if (!copy) return std::unexpected(copy.error());
            io.previous[size_t(r)] = *copy;
        }
    // Outputs: fresh buffers of the resource's shape.
    PendingState state{stage, name, &b, {}};
    for (Resource r : d.writes) {
        const size_t count = IsPerCamera(r) ? scene.render.cameras.size() : 1;
        if (!d.advancesState) io.current[size_t(r)].clear();
        for (size_t n = 0; n < count; ++n) {
            auto made = b.CreateBuffer(ResourceFormat(r), ResourceExtent(r, scene));
            if (!made) return std::unexpected(made.error());
            if (d.advancesState) {
                io.next[size_t(r)] = made->get();
                state.outputs.emplace_back(r, std::move(*made));
            } else {
                io.current[size_t(r)].push_back(*hold(std::move(*made)));
            }
        }
    }
    StageCallRecord record;
    CB_TRY(CallStage(stage, b, scene, host, io, record));
    if (callRecord) *callRecord = record;
    if (d.advancesState && pending) pending->push_back(std::move(state));
    return {};
}
}  // namespace

Result<std::vector<ConformRow>> RunConformance(const Scene& requested, Backend& cpu,
                                               std::span<const OpenedBackend> others, const ConformProgress& afterStep,
                                               const std::string& differenceDir, uint32_t attempt) {
    // Stages are compared whole: time-slicing changes when a stage's work is done, not what it computes
    // (tests/TimeSlice*Test.cpp check that), and unsliced every step draws render.frames_per_step frames.
    Scene scene = requested;
    scene.render.slicesPerFrame = 0;
    Tally tally;
    tally.differenceDir = differenceDir;
    tally.attempt = attempt;
    auto sim = Simulation::Create(scene, cpu, /*everyStepOutputs=*/true);
    if (!sim) return std::unexpected(sim.error());

    struct Candidate {
        std::string name;
        Backend* backend;
    };
    std::vector<Candidate> candidates;
    std::vector<ConformRow> unavailable;
    for (const OpenedBackend& other : others) {
        if (other.backend) {
            candidates.push_back({other.name, other.backend.get()});
            continue;
        }
        ConformRow row;
        row.stage = "(all)";
        row.backend = other.name;
        row.status = "skipped";
        row.detail = other.reason;
        unavailable.push_back(row);
    }

    for (uint32_t t = 0; t < scene.steps; ++t) {
        std::vector<PendingState> pending;
        // At the observer every stage of step t has run on the CPU, and the
        // state is still step t's: each backend's stages get the CPU's inputs.
        auto observe = [&](const Simulation& s) -> Status {
            for (Candidate& c : candidates) {
                Backend& b = *c.backend;
                for (Stage stage : s.Schedule()) {
                    const StageDescriptor& d = Describe(stage);
                    if (!b.Supports(stage)) {
                        // Rows of state-advancing stages come after the others, as they are compared later.
                        if (!d.advancesState) {
                            ConformRow& row = tally.Row(std::string(StageName(stage)), c.name, "", 0);
                            row.status = "skipped";
                            row.detail = c.name + " does not implement it yet";
                        } else {
                            pending.push_back({stage, c.name, nullptr, {}});
                        }
                        continue;
                    }
                    // A renderer draws render.frames_per_step frames a step; the CPU's own run kept the last,
                    // and the earlier ones are drawn on the CPU here from the same inputs.
                    const uint32_t frames = d.renderer ? std::max(scene.render.framesPerStep, 1u) : 1;
                    for (uint32_t f = 0; f < frames; ++f) {
                        const bool lastFrame = f + 1 == frames;
                        std::vector<std::unique_ptr<Buffer>> cpuOwned;
                        StageBuffers cpuIo;
                        if (!lastFrame)
                            CB_TRY(RunOnCopies(stage, scene, cpu, s, {t, s.RasterList(), f, 0, {}}, cpuOwned, cpuIo));
                        std::vector<std::unique_ptr<Buffer>> owned;
                        StageBuffers io;
                        StageCallRecord got;
                        if (Status run = RunOnCopies(stage, scene, b, s, {t, s.RasterList(), f, 0, {}}, owned, io, &cpu,
                                                     d.advancesState ? &pending : nullptr, c.name, &got);
                            !run)
                            return run;
                        if (d.advancesState) continue;
                        for (Resource r : d.writes)
                            for (size_t n = 0; n < io.current[size_t(r)].size(); ++n) {
                                std::string camera = IsPerCamera(r) ? scene.render.cameras[n].name : "";
                                if (frames > 1) camera += " frame " + std::to_string(f);
                                const Buffer& ref = lastFrame ? *s.Get(r, n) : *cpuIo.current[size_t(r)][n];
                                CB_TRY(CompareOutput(tally, scene, stage, c.name, t, cpu, ref, b,
                                                     *io.current[size_t(r)][n], camera));
                            }
                        if (stage == Stage::Density) {
                            // The cover count, against the CPU's density run again on the same copies.
                            std::vector<std::unique_ptr<Buffer>> refOwned;
                            StageBuffers refIo;
                            StageCallRecord ref;
                            CB_TRY(RunOnCopies(stage, scene, cpu, s, {t, s.RasterList(), f, 0, {}}, refOwned, refIo,
                                               nullptr, nullptr, "", &ref));
                            ConformRow& row = tally.Row(kCoverRowStage, c.name, "bit-exact", 0);
                            if (!ref.coveredColumns || !got.coveredColumns) {
                                row.status = "fail";
                                row.detail = "step " + std::to_string(t) + ": " +
                                             (ref.coveredColumns ? c.name : std::string("cpu")) +
                                             " returned no cover count";
                            } else {
                                uint32_t cover = *got.coveredColumns;
                                if (ConformTestMismatch(c.name, kCoverRowStage, attempt)) ++cover;
                                FoldCoverComparison(row, t, *ref.coveredColumns, cover);
                            }
                        }
                    }
                }
            }
            return {};
        };
        StepRecord record;
        if (Status s = (*sim)->Step(record, observe); !s) return std::unexpected(s.error());
        // Stages that advance the state: each backend stepped from the CPU's state t; compare with the CPU's t+1.
        for (PendingState& p : pending) {
            if (!p.owner) {
                ConformRow& row = tally.Row(std::string(StageName(p.stage)), p.backend, "", 0);
                row.status = "skipped";
                row.detail = p.backend + " does not implement it yet";
                continue;
            }
            for (auto& [r, buffer] : p.outputs)
                CB_TRY(CompareOutput(tally, scene, p.stage, p.backend, t, cpu, *(*sim)->Get(r), *p.owner, *buffer, ""));
        }
        if (afterStep) afterStep(t, tally.Rows());
    }
    std::vector<ConformRow> rows = tally.Rows();
    rows.insert(rows.end(), unavailable.begin(), unavailable.end());
    return rows;
}

report::Table ConformTable(const std::vector<ConformRow>& rows) {
    using report::Column;
    report::Table table({Column("stage").Width(13).Separator("  "), Column("backend").Width(8),
                         Column("result").Width(8), Column("rule").Width(28),
                         Column("worst").Real("%.4g").Width(12).AlignRight(), Column("where").Separator("  ")},
                        report::TextLayout::Columns);
    for (const ConformRow& r : rows) table.rows.push_back({r.stage, r.backend, r.status, r.rule, r.worst, r.detail});
    return table;
}

nlohmann::json ConformJson(const Scene& scene, const std::vector<ConformRow>& rows) {
    nlohmann::json list = nlohmann::json::array();
    for (const ConformRow& r : rows)
        list.push_back({{"stage", r.stage},
                        {"backend", r.backend},
                        {"status", r.status},
                        {"rule", r.rule},
                        {"worst", r.worst},
                        {"tolerance", r.tolerance},
                        {"detail", r.detail},
                        {"difference_image", r.differenceImage}});
    return {{"format", "cloudbench-conform/1"},
            {"scene", scene.name},
            {"steps", scene.steps},
            {"results", list},
            {"coverage", ConformCoverage(scene, rows)}};
}

nlohmann::json ConformCoverage(const Scene& scene, const std::vector<ConformRow>& rows) {
    auto options = [&](const std::string& stage) -> nlohmann::json {
        if (stage == "ca") return {{"wind", scene.ca.HasWind()}};
        if (stage == "smooth") return {{"radius", scene.smooth.radius}};
        if (stage == "density" || stage == kCoverRowStage)
            return {{"tile", scene.density.tile}, {"band", scene.density.band}, {"cld", scene.stages.Has(Stage::Ca)}};
        if (stage == "shade")
            return {{"attenuation", AttenuationKindName(scene.shade.attenuation)},
                    {"filter", SampleFilterName(scene.shade.filter)},
                    {"resolution", scene.shade.resolution},
                    {"storage", StorageFormatName(scene.shade.storage)},
                    {"scattering", scene.shade.scattering},
                    {"phase", scene.shade.scattering ? PhaseKindName(scene.phase.kind) : "none"}};
        if (stage == "shadow") return {{"form", ShadowFormName(scene.shadow.form)}};
        if (stage == "render_splat")
            return {{"phase", PhaseKindName(scene.phase.kind)},
                    {"culling", scene.splat.culling},
                    {"skipping", scene.splat.skipping},
                    {"storage", StorageFormatName(scene.shade.storage)},
                    {"cameras", scene.render.cameras.size()},
                    {"frames_per_step", std::max(scene.render.framesPerStep, 1u)}};
        return nlohmann::json::object();
    };
    nlohmann::json coverage = nlohmann::json::object();
    for (const ConformRow& r : rows) {
        if (r.stage == "(all)" || r.status == "skipped" || IsBrokenStatus(r.status)) continue;
        if (!coverage.contains(r.stage))
            coverage[r.stage] = {{"options", options(r.stage)}, {"compared_on", nlohmann::json::array()}};
        coverage[r.stage]["compared_on"].push_back(r.backend);
    }
    return coverage;
}

void FoldCoverComparison(ConformRow& row, uint32_t step, uint32_t cpuCover, uint32_t backendCover) {
    const double diff = std::fabs(double(cpuCover) - double(backendCover));
    // The detail names the step of the worst difference (the latest step while all agree).
    if (row.detail.empty() || diff > row.worst || (diff == 0 && row.worst == 0)) {
        row.worst = diff;
        row.detail = "step " + std::to_string(step) + ": cpu " + std::to_string(cpuCover) + " columns, " +
                     row.backend + " " + std::to_string(backendCover);
    }
    if (diff > 0) row.status = "fail";
}

bool IsConformFailure(const ConformRow& row) { return row.status == "fail" || IsBrokenStatus(row.status); }

void MergeRerun(std::vector<ConformRow>& first, const std::vector<ConformRow>& rerun, uint32_t attempt) {
    for (ConformRow& row : first) {
        if (!IsConformFailure(row)) continue;
        auto again = std::ranges::find_if(
            rerun, [&](const ConformRow& r) { return r.stage == row.stage && r.backend == row.backend; });
        if (again == rerun.end() || again->status != "pass") continue;
        const std::string why = row.detail;
        const std::string was = row.status;
        row = *again;
        row.status = "flaky";
        row.detail = "passed on rerun " + std::to_string(attempt) + "; the first run: " + was +
                     (why.empty() ? "" : ", " + why);
    }
}

bool ConformBaseline::Lists(const std::string& stage, const std::string& backend) const {
    return std::ranges::find(knownFailures, std::pair{stage, backend}) != knownFailures.end();
}

Result<ConformBaseline> ParseConformBaseline(const std::string& file, const std::string& text) {
    ConformBaseline baseline;
    std::istringstream in(text);
    std::string line;
    for (uint32_t number = 1; std::getline(in, line); ++number) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const size_t start = line.find_first_not_of(" \t");
        if (start == std::string::npos || line[start] == '#') continue;
        // The first three fields; further ones (a conform.csv's rule, worst, ...) are ignored.
        std::vector<std::string> fields;
        size_t at = 0;
        while (fields.size() < 3) {
            const size_t comma = line.find(',', at);
            std::string field = line.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
            const size_t b = field.find_first_not_of(" \t"), e = field.find_last_not_of(" \t");
            fields.push_back(b == std::string::npos ? "" : field.substr(b, e - b + 1));
            if (comma == std::string::npos) break;
            at = comma + 1;
        }
        auto bad = [&](const std::string& reason) -> Result<ConformBaseline> {
            return MakeError(file + ": line " + std::to_string(number) + ": " + reason);
        };
        if (fields.size() < 3) return bad("expected stage,backend,status");
        if (fields[0] == "stage" && fields[1] == "backend" && fields[2] == "status") continue;  // a CSV header
        if (fields[0].empty()) return bad("empty stage");
        if (fields[1].empty()) return bad("empty backend");
        const std::string& status = fields[2];
        if (status == "fail" || IsBrokenStatus(status) || status == "expected-fail") {
            if (baseline.Lists(fields[0], fields[1]))
                return bad(fields[0] + "," + fields[1] + " is listed twice");
            baseline.knownFailures.emplace_back(fields[0], fields[1]);
        } else if (status != "pass" && status != "skipped" && status != "flaky" && status != "unexpected-pass") {
            return bad("unknown status '" + status +
                       "' (fail, failed, crashed, timed out, out of memory or expected-fail list a known "
                       "failure; pass, skipped, flaky and unexpected-pass are ignored)");
        }
    }
    return baseline;
}

Result<ConformBaseline> LoadConformBaseline(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return MakeError(file + ": cannot read: " + std::strerror(errno));
    std::ostringstream text;
    text << in.rdbuf();
    return ParseConformBaseline(file, text.str());
}

void ApplyBaseline(std::vector<ConformRow>& rows, const ConformBaseline& baseline) {
    for (ConformRow& row : rows) {
        if (!baseline.Lists(row.stage, row.backend)) continue;
        if (IsConformFailure(row)) {
            row.detail = "known failure (" + row.status + ")" + (row.detail.empty() ? "" : ": " + row.detail);
            row.status = "expected-fail";
        } else if (row.status == "pass") {
            row.status = "unexpected-pass";
            row.detail = "listed in the baseline as a failure" + (row.detail.empty() ? "" : "; " + row.detail);
        }
    }
}

int ConformExitCode(const std::vector<ConformRow>& rows) {
    bool failed = false, compared = false, broken = false;
    for (const ConformRow& r : rows) {
        failed |= r.status == "fail" || r.status == "unexpected-pass";
        broken |= IsBrokenStatus(r.status);
        compared |= r.status != "skipped";
    }
    // A backend that crashed or could not run its stages is a failure (1), before a check that failed (5).
    if (broken) return kExitFailed;
    if (failed) return kExitNonConformant;
    return compared ? kExitOk : kExitNoBackend;
}

namespace {
std::string CsvField(const std::string& text) {
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) {
        if (c == '"') quoted += '"';
        quoted += c;
    }
    return quoted + "\"";
}
}  // namespace

std::string ConformCsv(const std::vector<ConformRow>& rows) {
    std::string csv = "stage,backend,status,rule,worst,tolerance,detail\n";
    char number[64];
    for (const ConformRow& r : rows) {
        csv += CsvField(r.stage) + "," + CsvField(r.backend) + "," + CsvField(r.status) + "," + CsvField(r.rule) + ",";
        std::snprintf(number, sizeof number, "%.9g", r.worst);
        csv += std::string(number) + ",";
        std::snprintf(number, sizeof number, "%.9g", r.tolerance);
        csv += std::string(number) + "," + CsvField(r.detail) + "\n";
    }
    return csv;
}

}  // namespace cb
