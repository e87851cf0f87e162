// The comparison engine of `cloudbench conform` (harness/conform/Conform.h): the CPU runs
// the scene, every other backend's stages get its inputs of each step, and each
// output is compared by the stage's rule. The tables, files, baseline and exit
// code of a finished run are in harness/conform/ConformOutput.cpp.
#include "harness/conform/Conform.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "core/plan/StageGraph.h"
#include "harness/platform/Command.h"
#include "harness/report/Report.h"
#include "harness/run/Simulation.h"
#include "harness/run/StageCall.h"

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

// The test-only switch CLOUDBENCH_TEST_CONFORM_MISMATCH=<backend>:<row stage>[:<attempts>][@<case>]
// (harness/conform/Conform.h): whether this backend's output of this row is to be perturbed on this attempt, in this
// case.
bool ConformTestMismatch(const std::string& backend, const std::string& stage, uint32_t attempt,
                         const std::string& caseName) {
    const char* value = std::getenv("CLOUDBENCH_TEST_CONFORM_MISMATCH");
    if (!value || !*value) return false;
    std::string text(value);
    if (const size_t at = text.find('@'); at != std::string::npos) {
        if (text.substr(at + 1) != caseName) return false;
        text.resize(at);
    }
    const size_t colon = text.find(':');
    if (colon == std::string::npos || text.substr(0, colon) != backend) return false;
    const std::string rest = text.substr(colon + 1);
    const size_t second = rest.find(':');
    if (rest.substr(0, second) != stage) return false;
    if (second == std::string::npos) return true;
    return attempt < uint32_t(std::strtoul(rest.c_str() + second + 1, nullptr, 10));
}

// The switch's variant CLOUDBENCH_TEST_CONFORM_MISMATCH_EVERY=1: a byte row's every element one code off
// (255 down, the rest up) instead of its first flipped, to test the share limit of a quantised rule.
bool ConformTestMismatchEveryElement() {
    const char* value = std::getenv("CLOUDBENCH_TEST_CONFORM_MISMATCH_EVERY");
    return value && std::string(value) == "1";
}

// The test-only switch's value variant CLOUDBENCH_TEST_CONFORM_MISMATCH_VALUE=nan|inf|-inf: a float row's first
// element set to that value instead of moved by 1 (with the backend "cpu", the reference's). Empty when unset or not
// one of the three.
std::optional<float> ConformTestMismatchValue() {
    const char* value = std::getenv("CLOUDBENCH_TEST_CONFORM_MISMATCH_VALUE");
    const std::string text = value ? value : "";
    if (text == "nan") return std::numeric_limits<float>::quiet_NaN();
    if (text == "inf") return std::numeric_limits<float>::infinity();
    if (text == "-inf") return -std::numeric_limits<float>::infinity();
    return std::nullopt;
}

// The first element where the CPU's or the backend's value is NaN or Inf, or size() where all are finite.
size_t FirstNonFinite(const std::vector<float>& ref, const std::vector<float>& got) {
    for (size_t v = 0; v < ref.size() && v < got.size(); ++v)
        if (!std::isfinite(ref[v]) || !std::isfinite(got[v])) return v;
    return ref.size();
}

// Accumulates the worst result of one stage x backend over the steps.
class Tally {
  public:
    std::string differenceDir;  // where renderer rows write their worst frame's difference image; "" = nowhere
    uint32_t attempt = 0;       // 0 first, 1.. for --flake-reruns (the test-only mismatch switch)
    std::string caseName;       // the case (--matrix), for the test-only mismatch switch
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
        if (!g->empty() && ConformTestMismatch(name, stageName, tally.attempt, tally.caseName)) {
            if (ConformTestMismatchEveryElement())  // one quantum off everywhere: within tolerance, over the share
                for (uint8_t& v : *g) v = v == 255 ? 254 : uint8_t(v + 1);
            else
                (*g)[0] ^= 0x80;
        }
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
    if (!g->empty() && ConformTestMismatch(name, stageName, tally.attempt, tally.caseName)) {
        if (const std::optional<float> planted = ConformTestMismatchValue())
            (*g)[0] = *planted;
        else
            (*g)[0] += (*g)[0] >= 0.5f ? -1.0f : 1.0f;
    }
    // The value variant with the backend "cpu": the reference's first element, against every other backend.
    if (const std::optional<float> planted = ConformTestMismatchValue();
        planted && !r->empty() && ConformTestMismatch("cpu", stageName, tally.attempt, tally.caseName))
        (*r)[0] = *planted;
    // Any NaN or Inf, the backend's or the CPU's, fails the row under every rule (no stage may return one, SPEC 12):
    // worst becomes inf, so a later step's finite worst never replaces this detail.
    if (const size_t v = FirstNonFinite(*r, *g); v < r->size()) {
        const double tolerance = rule.kind == CompareRule::Kind::BitExact ? 0
                                 : rule.kind == CompareRule::Kind::Image  ? rule.limit
                                                                          : rule.tolerance;
        ConformRow& row = tally.Row(
            stageName, name, rule.kind == CompareRule::Kind::BitExact ? "bit-exact" : rule.Text(d.symbol), tolerance);
        if (row.worst != std::numeric_limits<double>::infinity()) {
            std::ostringstream where;
            where << "step " << t;
            if (rule.kind == CompareRule::Kind::Image)  // (3, width, height): channel fastest
                where << " camera " << camera << " pixel (" << (v / 3) % e.ny << ", " << v / (3 * size_t(e.ny))
                      << ") channel " << v % 3;
            else
                where << " at " << Where(e, v);
            where << ": not finite: cpu " << (*r)[v] << ", " << name << " " << (*g)[v];
            row.worst = std::numeric_limits<double>::infinity();
            row.detail = where.str();
        }
        row.status = "fail";
        return {};
    }
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
            auto compared = CompareImages(*r, *g, width, height, rule);
            if (!compared) return std::unexpected(compared.error());
            const ImageComparison& cmp = *compared;
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
                                               const std::string& differenceDir, uint32_t attempt,
                                               const std::string& caseName) {
    // Stages are compared whole: time-slicing changes when a stage's work is done, not what it computes
    // (tests/TimeSlice*Test.cpp check that), and unsliced every step draws render.frames_per_step frames.
    Scene scene = requested;
    scene.render.slicesPerFrame = 0;
    Tally tally;
    tally.differenceDir = differenceDir;
    tally.attempt = attempt;
    tally.caseName = caseName;
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
                                if (ConformTestMismatch(c.name, kCoverRowStage, attempt, caseName)) ++cover;
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

void FoldCoverComparison(ConformRow& row, uint32_t step, uint32_t cpuCover, uint32_t backendCover) {
    const double diff = std::fabs(double(cpuCover) - double(backendCover));
    // The detail names the step of the worst difference (the latest step while all agree).
    if (row.detail.empty() || diff > row.worst || (diff == 0 && row.worst == 0)) {
        row.worst = diff;
        row.detail = "step " + std::to_string(step) + ": cpu " + std::to_string(cpuCover) + " columns, " + row.backend +
                     " " + std::to_string(backendCover);
    }
    if (diff > 0) row.status = "fail";
}

}  // namespace cb
