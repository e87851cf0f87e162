#include "harness/Conform.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <sstream>

#include "core/Random.h"
#include "harness/Report.h"
#include "harness/Simulation.h"
#include "harness/StageParams.h"

namespace cb {
namespace {

template <typename T>
Result<std::vector<T>> Read(Backend& backend, const Buffer& buffer) {
    return Download<T>(backend, buffer);
}

template <typename T>
Result<std::unique_ptr<Buffer>> Filled(Backend& backend, BufferFormat format, Extent3 extent, const std::vector<T>& data) {
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

// Accumulates the worst result of one stage x backend over the steps.
class Tally {
  public:
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
            d << differ << " differ at step " << step << ", first " << Where(e, first) << ": cpu " << +ref[first] << ", "
              << backend << " " << +got[first];
            row.detail = d.str();
        }
        if (differ) row.status = "fail";
    }
    // |a - b| <= tolerance everywhere.
    void Within(const std::string& stage, const std::string& backend, uint32_t step, const Extent3& e,
                const std::vector<float>& ref, const std::vector<float>& got, double tolerance, const std::string& rule) {
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

Result<std::vector<ConformRow>> RunConformance(const Scene& scene, Backend& cpu,
                                               std::span<const OpenedBackend> others) {
    Tally tally;
    auto sim = Simulation::Create(scene, cpu, /*everyStepOutputs=*/true);
    if (!sim) return std::unexpected(sim.error());
    const Extent3 e = scene.grid.size;

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

    // The CPU's state before the step (the automaton's input) is read before stepping.
    for (uint32_t t = 0; t < scene.steps; ++t) {
        std::vector<uint8_t> stateBefore[3];
        if (scene.stages.Has(Stage::Ca)) {
            const Buffer* fields[3] = {(*sim)->Hum(), (*sim)->Act(), (*sim)->Cld()};
            for (int f = 0; f < 3; ++f) {
                auto d = Read<uint8_t>(cpu, *fields[f]);
                if (!d) return std::unexpected(d.error());
                stateBefore[f] = std::move(*d);
            }
        }
        Status checks;
        auto observe = [&](const Simulation& s) -> Status {
            for (Candidate& c : candidates) {
                Backend& b = *c.backend;
                const StageSet& st = scene.stages;
                auto skip = [&](Stage stage) {
                    if (b.Supports(stage)) return false;
                    ConformRow& row = tally.Row(std::string(StageName(stage)), c.name, "", 0);
                    row.status = "skipped";
                    row.detail = c.name + " does not implement it yet";
                    return true;
                };
                if (st.Has(Stage::Region) && !skip(Stage::Region)) {
                    auto out = b.CreateBuffer(BufferFormat::U8, e);
                    if (!out) return std::unexpected(out.error());
                    CB_TRY(b.Region(s.RasterList(), **out));
                    auto ref = Read<uint8_t>(cpu, *s.Region());
                    auto got = Read<uint8_t>(b, **out);
                    if (!ref || !got) return MakeError("region: download failed");
                    // |dR| <= 1 everywhere and at most 0.5 % of voxels differ.
                    ConformRow& row = tally.Row("region", c.name, "|dR| <= 1, <= 0.5 % differ", 1);
                    size_t differ = 0, at = 0;
                    int worst = 0;
                    for (size_t v = 0; v < ref->size(); ++v) {
                        const int d = std::abs(int((*ref)[v]) - int((*got)[v]));
                        differ += d != 0;
                        if (d > worst) worst = d, at = v;
                    }
                    if (worst > row.worst) {
                        row.worst = worst;
                        row.detail = "step " + std::to_string(t) + " at " + Where(e, at) + ": cpu " +
                                     std::to_string((*ref)[at]) + ", " + c.name + " " + std::to_string((*got)[at]);
                    }
                    if (worst > 1 || double(differ) > 0.005 * double(ref->size())) row.status = "fail";
                }
                if (st.Has(Stage::Smooth) && !skip(Stage::Smooth)) {
                    auto cld = Filled(b, BufferFormat::Bits, e, stateBefore[2]);
                    auto q = b.CreateBuffer(BufferFormat::F32, e);
                    if (!cld || !q) return MakeError("smooth: allocation failed");
                    CB_TRY(b.Smooth(scene.smooth.radius, **cld, **q));
                    auto ref = Read<float>(cpu, *s.Q());
                    auto got = Read<float>(b, **q);
                    if (!ref || !got) return MakeError("smooth: download failed");
                    tally.Exact("smooth", c.name, t, e, *ref, *got);
                }
                if (st.Has(Stage::Density) && !skip(Stage::Density)) {
                    auto qData = Read<float>(cpu, *s.Q());
                    if (!qData) return std::unexpected(qData.error());
                    auto q = Filled(b, BufferFormat::F32, e, *qData);
                    auto cld = Filled(b, BufferFormat::Bits, e, stateBefore[2]);
                    auto D = b.CreateBuffer(BufferFormat::F32, s.ColumnSum()->Extent());
                    auto tiles = b.CreateBuffer(BufferFormat::U8, s.Tiles()->Extent());
                    auto bands = b.CreateBuffer(BufferFormat::U8, s.Bands()->Extent());
                    if (!q || !cld || !D || !tiles || !bands) return MakeError("density: allocation failed");
                    DensityOutputs out{D->get(), tiles->get(), bands->get(), 0};
                    CB_TRY(b.Density({scene.density.tile, scene.density.band}, **q, cld->get(), out));
                    tally.Exact("density", c.name, t, s.ColumnSum()->Extent(), *Read<float>(cpu, *s.ColumnSum()),
                                *Read<float>(b, **D));
                    tally.Exact("density", c.name, t, s.Tiles()->Extent(), *Read<uint8_t>(cpu, *s.Tiles()),
                                *Read<uint8_t>(b, **tiles));
                    tally.Exact("density", c.name, t, s.Bands()->Extent(), *Read<uint8_t>(cpu, *s.Bands()),
                                *Read<uint8_t>(b, **bands));
                }
                if (st.Has(Stage::Shade) && !skip(Stage::Shade) && s.T()) {
                    auto qData = Read<float>(cpu, *s.Q());
                    if (!qData) return std::unexpected(qData.error());
                    auto q = Filled(b, BufferFormat::F32, e, *qData);
                    auto T = b.CreateBuffer(BufferFormat::F32, e);
                    if (!q || !T) return MakeError("shade: allocation failed");
                    const ShadeParams p = MakeShadeParams(scene);
                    CB_TRY(b.Shade(p, **q, **T));
                    const double tolerance = p.storage == StorageFormat::Fp32 ? 1e-5 : StorageQuantum(p.storage);
                    char rule[64];
                    std::snprintf(rule, sizeof rule, "|dT| <= %g", tolerance);
                    tally.Within("shade", c.name, t, e, *Read<float>(cpu, *s.T()), *Read<float>(b, **T), tolerance, rule);
                }
                if (st.Has(Stage::Shadow) && !skip(Stage::Shadow) && s.Shadow()) {
                    auto dData = Read<float>(cpu, *s.ColumnSum());
                    if (!dData) return std::unexpected(dData.error());
                    const Extent3 map = s.ColumnSum()->Extent();
                    auto D = Filled(b, BufferFormat::F32, map, *dData);
                    auto G = b.CreateBuffer(BufferFormat::F32, map);
                    if (!D || !G) return MakeError("shadow: allocation failed");
                    const ShadowParams p = MakeShadowParams(scene);
                    CB_TRY(b.Shadow(p, **D, **G));
                    tally.Within("shadow", c.name, t, map, *Read<float>(cpu, *s.Shadow()), *Read<float>(b, **G), 1e-5,
                                 "|dG| <= 1e-05");
                }
                if (st.Has(Stage::RenderSplat) && !skip(Stage::RenderSplat) && s.Image(0)) {
                    // Feed the CPU's q of both steps, T and occupancy; render every camera.
                    auto copy = [&](const Buffer* from, BufferFormat format) -> Result<std::unique_ptr<Buffer>> {
                        if (!from) return std::unique_ptr<Buffer>();
                        std::vector<std::byte> data(from->CanonicalBytes());
                        CB_TRY(cpu.Download(*from, data));
                        auto to = b.CreateBuffer(format, from->Extent());
                        if (!to) return std::unexpected(to.error());
                        CB_TRY(b.Upload(**to, data));
                        return std::move(*to);
                    };
                    auto qp = copy(s.QPrev(), BufferFormat::F32);
                    auto qc = copy(s.Q(), BufferFormat::F32);
                    auto T = copy(s.T(), BufferFormat::F32);
                    auto tp = copy(s.TilesPrev(), BufferFormat::U8);
                    auto tc = copy(s.Tiles(), BufferFormat::U8);
                    auto bp = copy(s.BandsPrev(), BufferFormat::U8);
                    auto bc = copy(s.Bands(), BufferFormat::U8);
                    if (!qp || !qc || !T || !tp || !tc || !bp || !bc)
                        return MakeError("render_splat: copying inputs failed");
                    const RenderSettings& rs = scene.render;
                    for (size_t n = 0; n < rs.cameras.size(); ++n) {
                        SplatParams p = MakeSplatParams(scene, rs.cameras[n]);
                        const SplatOrder order = MakeSplatOrder(p.camera, e, scene.grid.origin, scene.grid.voxelSize);
                        p.order = &order;
                        auto image = b.CreateBuffer(BufferFormat::F32, {3, rs.width, rs.height});
                        if (!image) return std::unexpected(image.error());
                        SplatInputs in{qp->get(), qc->get(), T->get(), tp->get(), tc->get(), bp->get(), bc->get()};
                        CB_TRY(b.RenderSplat(p, in, **image, nullptr));
                        auto ref = Read<float>(cpu, *s.Image(n));
                        auto got = Read<float>(b, **image);
                        if (!ref || !got) return MakeError("render_splat: download failed");
                        const ImageComparison cmp = CompareImages(*ref, *got, rs.width, rs.height);
                        ConformRow& row = tally.Row("render_splat", c.name, "2/255 on 99.9 %, 8/255 max", 8.0 / 255.0);
                        if (!(cmp.maxError <= row.worst)) {
                            row.worst = cmp.maxError;
                            char detail[256];
                            std::snprintf(detail, sizeof detail,
                                          "step %u camera %s: worst pixel (%d, %d), %zu pixels over 2/255, PSNR %.1f dB",
                                          t, rs.cameras[n].name.c_str(), cmp.worstX, cmp.worstY, cmp.pixelsOver2, cmp.psnr);
                            row.detail = detail;
                        }
                        if (!cmp.Passes()) row.status = "fail";
                    }
                }
            }
            return {};
        };
        StepRecord record;
        if (Status s = (*sim)->Step(record, observe); !s) return std::unexpected(s.error());
        // The automaton: each backend steps from the CPU's state t with R_t; compare with the CPU's t+1.
        if (scene.stages.Has(Stage::Ca)) {
            std::vector<uint8_t> after[3];
            const Buffer* fields[3] = {(*sim)->Hum(), (*sim)->Act(), (*sim)->Cld()};
            for (int f = 0; f < 3; ++f) after[f] = *Read<uint8_t>(cpu, *fields[f]);
            const std::vector<uint8_t> region = *Read<uint8_t>(cpu, *(*sim)->Region());
            for (Candidate& c : candidates) {
                Backend& b = *c.backend;
                if (!b.Supports(Stage::Ca)) {
                    ConformRow& row = tally.Row("ca", c.name, "", 0);
                    row.status = "skipped";
                    row.detail = c.name + " does not implement it yet";
                    continue;
                }
                std::unique_ptr<Buffer> in[3], out[3];
                for (int f = 0; f < 3; ++f) {
                    auto buffer = Filled(b, BufferFormat::Bits, e, stateBefore[f]);
                    auto o = b.CreateBuffer(BufferFormat::Bits, e);
                    if (!buffer || !o) return MakeError("ca: allocation failed");
                    in[f] = std::move(*buffer);
                    out[f] = std::move(*o);
                }
                auto r = Filled(b, BufferFormat::U8, e, region);
                if (!r) return std::unexpected(r.error());
                std::vector<int32_t> sx, sy;
                if (scene.ca.HasWind())
                    for (const SliceShift& shift : scene.ca.windShift) sx.push_back(shift.sx), sy.push_back(shift.sy);
                CaStepParams p{scene.ca.seed, t, QuantizeProbability(scene.ca.pExt), QuantizeProbability(scene.ca.pHum),
                               QuantizeProbability(scene.ca.pAct), sx, sy};
                CB_TRY(b.CaStep(p, {in[0].get(), in[1].get(), in[2].get()}, **r, {out[0].get(), out[1].get(), out[2].get()}));
                for (int f = 0; f < 3; ++f) tally.Exact("ca", c.name, t, e, after[f], *Read<uint8_t>(b, *out[f]));
            }
        }
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
        list.push_back({{"stage", r.stage}, {"backend", r.backend}, {"status", r.status}, {"rule", r.rule},
                        {"worst", r.worst}, {"tolerance", r.tolerance}, {"detail", r.detail}});
    return {{"format", "cloudbench-conform/1"}, {"scene", scene.name}, {"steps", scene.steps}, {"results", list}};
}

}  // namespace cb
