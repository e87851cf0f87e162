// The simulation stages of the GPU pass extents test (GpuExtents.h): noise,
// region, ca, smooth, density, shade and shadow, each run on a GPU backend and
// on the CPU from the same inputs and compared by the stage's rule, as
// tests/ConformanceTest.cpp and ConformanceRenderTest.cpp compare them. Every
// output buffer on the GPU starts filled with a hash, so that a voxel a pass
// does not reach keeps a value no stage writes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <sstream>
#include <vector>

#include "core/math/Random.h"
#include "core/math/Shading.h"
#include "core/plan/StageGraph.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/GpuExtents.h"
#include "tests/TestUtil.h"
#if CLOUDBENCH_HAVE_VK
#include "impl_vk/BackendVk.h"
#endif

namespace cb::extents {
namespace {

// A buffer of `format` on `backend` holding a hash (never what a stage writes there).
std::unique_ptr<Buffer> ExtStaleBuffer(Backend& backend, BufferFormat format, Extent3 e) {
    if (format == BufferFormat::F32) {
        std::vector<float> v(e.Count());
        for (size_t i = 0; i < v.size(); ++i) v[i] = 7.0f + float(LowBias32(uint32_t(i) + 99u) % 1000u);
        return test::MakeFilled(backend, format, e, v);
    }
    std::vector<uint8_t> v(e.Count());
    for (size_t i = 0; i < v.size(); ++i) {
        const uint32_t h = LowBias32(uint32_t(i) * 2654435761u + 5u);
        v[i] = uint8_t(format == BufferFormat::Bits ? (h & 1u) : 200u + (h & 31u));
    }
    return test::MakeFilled(backend, format, e, v);
}

// "(i, j, k)" of element v of extent e.
std::string ExtWhere(const Extent3& e, size_t v) {
    std::ostringstream s;
    s << "(" << v % e.nx << ", " << (v / e.nx) % e.ny << ", " << v / (size_t(e.nx) * e.ny) << ")";
    return s.str();
}

// Bit for bit, with the first difference and the count.
template <typename T>
void ExtExpectExact(const std::vector<T>& cpu, const std::vector<T>& gpu, const Extent3& e, const std::string& what) {
    ASSERT_EQ(cpu.size(), gpu.size()) << what;
    size_t first = cpu.size(), count = 0;
    for (size_t v = 0; v < cpu.size(); ++v)
        if (std::memcmp(&cpu[v], &gpu[v], sizeof(T)) != 0) first = first == cpu.size() ? v : first, ++count;
    if (count == 0) return;
    ADD_FAILURE() << what << ": " << count << " of " << cpu.size() << " differ; first at " << ExtWhere(e, first)
                  << ": cpu " << +cpu[first] << ", gpu " << +gpu[first];
}

// max |cpu - gpu| <= tolerance (a NaN fails).
void ExtExpectWithin(const std::vector<float>& cpu, const std::vector<float>& gpu, const Extent3& e,
                     double tolerance, const std::string& what) {
    ASSERT_EQ(cpu.size(), gpu.size()) << what;
    double worst = 0;
    size_t at = 0;
    for (size_t v = 0; v < cpu.size(); ++v) {
        const double d = std::fabs(double(cpu[v]) - double(gpu[v]));
        if (!(d <= worst)) worst = d, at = v;
    }
    EXPECT_LE(worst, tolerance) << what << ": worst at " << ExtWhere(e, at) << ": cpu " << cpu[at] << ", gpu "
                                << gpu[at];
}

void ExtNoise(Backend& cpu, Backend& gpu, const Extent3& e) {
    NoiseSettings settings;  // Perlin, with towers and detail, so that every term of the formula runs
    settings.seed = 11;
    settings.towers = {{{e.nx * 0.5, e.ny * 0.5, e.nz * 0.5}, {3, 3, 2}, 0.4}};
    settings.detail.enabled = true;
    settings.detail.size = 8, settings.detail.frequency = 2, settings.detail.fbm.octaves = 2;
    const NoiseParams params{3, &settings, e};
    auto ref = test::MakeBuffer(cpu, BufferFormat::F32, e);
    auto got = ExtStaleBuffer(gpu, BufferFormat::F32, e);
    ASSERT_TRUE(cpu.Noise(params, *ref));
    const Status s = gpu.Noise(params, *got);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    ExtExpectWithin(test::Read<float>(cpu, *ref), test::Read<float>(gpu, *got), e,
                    cb::Describe(Stage::Noise).rule(Scene{}).tolerance, "q");
}

// SPEC 2: |dR| <= 1 everywhere and at most 0.5 % of voxels differ.
void ExtRegion(Backend& cpu, Backend& gpu, const Extent3& e) {
    const std::vector<RasterEllipsoid> list = test::RandomEllipsoids(e, 3);
    auto ref = test::MakeBuffer(cpu, BufferFormat::U8, e);
    auto got = ExtStaleBuffer(gpu, BufferFormat::U8, e);
    ASSERT_TRUE(cpu.Region(list, *ref));
    const Status s = gpu.Region(list, *got);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    const auto a = test::Read<uint8_t>(cpu, *ref), b = test::Read<uint8_t>(gpu, *got);
    size_t differ = 0, worst = 0;
    int worstDelta = 0;
    for (size_t v = 0; v < a.size(); ++v) {
        const int d = std::abs(int(a[v]) - int(b[v]));
        differ += d != 0;
        if (d > worstDelta) worstDelta = d, worst = v;
    }
    EXPECT_LE(worstDelta, 1) << "R worst at " << ExtWhere(e, worst) << ": cpu " << +a[worst] << ", gpu " << +b[worst];
    EXPECT_LE(double(differ), 0.005 * double(a.size())) << differ << " voxels of R differ";
}

// SPEC 3: the initial state, then a step from the CPU's state (with a wind shift on every slice when asked), bit
// for bit.
void ExtCa(Backend& cpu, Backend& gpu, const Extent3& e, bool wind) {
    const CaInitParams init{17, QuantizeProbability(0.4), QuantizeProbability(0.05)};
    std::unique_ptr<Buffer> ref[3], refOut[3], got[3], gotOut[3];
    for (int f = 0; f < 3; ++f) {
        ref[f] = test::MakeBuffer(cpu, BufferFormat::Bits, e);
        refOut[f] = test::MakeBuffer(cpu, BufferFormat::Bits, e);
        got[f] = ExtStaleBuffer(gpu, BufferFormat::Bits, e);
        gotOut[f] = ExtStaleBuffer(gpu, BufferFormat::Bits, e);
    }
    ASSERT_TRUE(cpu.CaInitialize(init, {ref[0].get(), ref[1].get(), ref[2].get()}));
    Status s = gpu.CaInitialize(init, {got[0].get(), got[1].get(), got[2].get()});
    ASSERT_TRUE(s.has_value()) << s.error().message;
    const char* names[3] = {"hum", "act", "cld"};
    for (int f = 0; f < 3; ++f)
        ExtExpectExact(test::Read<uint8_t>(cpu, *ref[f]), test::Read<uint8_t>(gpu, *got[f]), e,
                       std::string("initial ") + names[f]);
    auto region = test::MakeBuffer(cpu, BufferFormat::U8, e);
    ASSERT_TRUE(cpu.Region(test::RandomEllipsoids(e, 5), *region));
    auto gotRegion = test::MakeFilled(gpu, BufferFormat::U8, e, test::Read<uint8_t>(cpu, *region));
    std::vector<int32_t> sx(e.nz), sy(e.nz);
    for (uint32_t k = 0; k < e.nz; ++k) sx[k] = int32_t(k % 3) - 1 + (k == 0 ? 2 : 0), sy[k] = k % 2 ? 1 : -1;
    CaStepParams p{17, 4, QuantizeProbability(0.2), QuantizeProbability(0.1), QuantizeProbability(0.05), {}, {}, {}};
    if (wind) p.shiftX = sx, p.shiftY = sy;
    ASSERT_TRUE(cpu.CaStep(p, {ref[0].get(), ref[1].get(), ref[2].get()}, *region,
                           {refOut[0].get(), refOut[1].get(), refOut[2].get()}));
    for (int f = 0; f < 3; ++f) {
        const std::vector<uint8_t> state = test::Read<uint8_t>(cpu, *ref[f]);
        ASSERT_TRUE(gpu.Upload(*got[f], std::as_bytes(std::span(state))));
    }
    s = gpu.CaStep(p, {got[0].get(), got[1].get(), got[2].get()}, *gotRegion,
                   {gotOut[0].get(), gotOut[1].get(), gotOut[2].get()});
    ASSERT_TRUE(s.has_value()) << s.error().message;
    for (int f = 0; f < 3; ++f)
        ExtExpectExact(test::Read<uint8_t>(cpu, *refOut[f]), test::Read<uint8_t>(gpu, *gotOut[f]), e,
                       std::string("stepped ") + names[f] + (wind ? " with wind" : ""));
}

// SPEC 4, bit for bit.
void ExtSmooth(Backend& cpu, Backend& gpu, const Extent3& e, int radius) {
    const std::vector<uint8_t> cld = test::RandomBits(e, 7, 3);
    auto refBits = test::MakeFilled(cpu, BufferFormat::Bits, e, cld);
    auto gotBits = test::MakeFilled(gpu, BufferFormat::Bits, e, cld);
    auto ref = test::MakeBuffer(cpu, BufferFormat::F32, e);
    auto got = ExtStaleBuffer(gpu, BufferFormat::F32, e);
    ASSERT_TRUE(cpu.Smooth(radius, *refBits, *ref));
    const Status s = gpu.Smooth(radius, *gotBits, *got);
    ASSERT_TRUE(s.has_value()) << s.error().message;
    ExtExpectExact(test::Read<float>(cpu, *ref), test::Read<float>(gpu, *got), e,
                   "q, radius " + std::to_string(radius));
}

// SPEC 5: D, tiles, bands and the cover, bit for bit, band 4 (a partial last band where nz % 4 != 0).
void ExtDensity(Backend& cpu, Backend& gpu, const Extent3& e, uint32_t tile) {
    const std::vector<uint8_t> cld = test::RandomBits(e, 13, 9);
    std::vector<float> q(e.Count(), 0.0f);
    Pcg32 rng(31);
    for (float& v : q) v = rng.Below(4) == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    const DensityParams params{tile, 4, {}};
    const Extent3 columns{e.nx, e.ny, 1}, tiles{CeilDiv(e.nx, tile), CeilDiv(e.ny, tile), 1},
        bands{tiles.nx, tiles.ny, CeilDiv(e.nz, 4u)};
    Backend* backends[2] = {&cpu, &gpu};
    std::unique_ptr<Buffer> in[2][2], out[2][3];
    DensityOutputs results[2];
    for (int n = 0; n < 2; ++n) {
        in[n][0] = test::MakeFilled(*backends[n], BufferFormat::F32, e, q);
        in[n][1] = test::MakeFilled(*backends[n], BufferFormat::Bits, e, cld);
        out[n][0] = ExtStaleBuffer(*backends[n], BufferFormat::F32, columns);
        out[n][1] = ExtStaleBuffer(*backends[n], BufferFormat::U8, tiles);
        out[n][2] = ExtStaleBuffer(*backends[n], BufferFormat::U8, bands);
        results[n] = {out[n][0].get(), out[n][1].get(), out[n][2].get(), 0};
        const Status s = backends[n]->Density(params, *in[n][0], in[n][1].get(), results[n]);
        ASSERT_TRUE(s.has_value()) << backends[n]->Name() << ": " << s.error().message;
    }
    ExtExpectExact(test::Read<float>(cpu, *out[0][0]), test::Read<float>(gpu, *out[1][0]), columns, "D");
    ExtExpectExact(test::Read<uint8_t>(cpu, *out[0][1]), test::Read<uint8_t>(gpu, *out[1][1]), tiles, "tiles");
    ExtExpectExact(test::Read<uint8_t>(cpu, *out[0][2]), test::Read<uint8_t>(gpu, *out[1][2]), bands, "bands");
    EXPECT_EQ(results[0].coveredColumns, results[1].coveredColumns) << "cover";
}

// SPEC 6, fp32: max |dT| <= 1e-5, for the sun overhead (the slices are the x-y planes) and an oblique one.
void ExtShade(Backend& cpu, Backend& gpu, const Extent3& e, uint32_t option) {
#if CLOUDBENCH_HAVE_VK
    auto* vk = dynamic_cast<vk::BackendVk*>(&gpu);
    if (vk) vk->SetShadeSweep(option >= 100 ? vk::BackendVk::ShadeSweep::Blocks : vk::BackendVk::ShadeSweep::Auto);
#endif
    Pcg32 rng(21);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    auto refQ = test::MakeFilled(cpu, BufferFormat::F32, e, q);
    auto gotQ = test::MakeFilled(gpu, BufferFormat::F32, e, q);
    for (const Vec3& sun : {Vec3{0, 0, 1}, SunDirection(0.44, 1.05)}) {
        ShadeParams p;
        p.sun = sun;
        p.resolution = int(option % 100);
        p.sigma = 0.01f;
        p.scattering = true;
        auto refT = test::MakeBuffer(cpu, BufferFormat::F32, e);
        auto gotT = ExtStaleBuffer(gpu, BufferFormat::F32, e);
        ASSERT_TRUE(cpu.Shade(p, *refQ, *refT));
        const Status s = gpu.Shade(p, *gotQ, *gotT);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        ExtExpectWithin(test::Read<float>(cpu, *refT), test::Read<float>(gpu, *gotT), e,
                        cb::Describe(Stage::Shade).rule(Scene{}).tolerance,
                        "T, sun z " + std::to_string(sun[2]) + ", f " + std::to_string(p.resolution));
    }
#if CLOUDBENCH_HAVE_VK
    if (vk) vk->SetShadeSweep(vk::BackendVk::ShadeSweep::Auto);
#endif
}

// SPEC 7: max |dG| <= 1e-5, beer and wang, an oblique sun.
void ExtShadow(Backend& cpu, Backend& gpu, const Extent3& e) {
    const Extent3 map{e.nx, e.ny, 1};
    Pcg32 rng(23);
    std::vector<float> D(map.Count());
    for (float& v : D) v = float(rng.Below(200)) / 64.0f;
    auto refD = test::MakeFilled(cpu, BufferFormat::F32, map, D);
    auto gotD = test::MakeFilled(gpu, BufferFormat::F32, map, D);
    for (ShadowForm form : {ShadowForm::Beer, ShadowForm::Wang}) {
        ShadowParams p;
        p.sun = SunDirection(0.5, 0.7);
        p.form = form;
        p.coverage = 0.7f, p.densityFactor = 0.8f, p.nz = e.nz;
        auto refG = test::MakeBuffer(cpu, BufferFormat::F32, map);
        auto gotG = ExtStaleBuffer(gpu, BufferFormat::F32, map);
        ASSERT_TRUE(cpu.Shadow(p, *refD, *refG));
        const Status s = gpu.Shadow(p, *gotD, *gotG);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        ExtExpectWithin(test::Read<float>(cpu, *refG), test::Read<float>(gpu, *gotG), map,
                        cb::Describe(Stage::Shadow).rule(Scene{}).tolerance, "G, form " + std::to_string(int(form)));
    }
}

}  // namespace

std::string Describe(const ExtentCase& c) {
    std::ostringstream s;
    s << "grid " << c.grid.nx << "x" << c.grid.ny << "x" << c.grid.nz << ", image " << c.width << "x" << c.height
      << ", option " << c.option;
    return s.str();
}

void RunSimulationExtentCase(Stage stage, Backend& gpu, const ExtentCase& c) {
    cpu::BackendCpu cpu(2);
    const Extent3 e = c.grid;
    switch (stage) {
        case Stage::Noise: return ExtNoise(cpu, gpu, e);
        case Stage::Region: return ExtRegion(cpu, gpu, e);
        case Stage::Ca: return ExtCa(cpu, gpu, e, c.option == 1);
        case Stage::Smooth: return ExtSmooth(cpu, gpu, e, int(c.option));
        case Stage::Density: return ExtDensity(cpu, gpu, e, c.option);
        case Stage::Shade: return ExtShade(cpu, gpu, e, c.option);
        case Stage::Shadow: return ExtShadow(cpu, gpu, e);
        default: ADD_FAILURE() << "no extent runner for " << StageName(stage);
    }
}

void RunExtentCase(Stage stage, Backend& gpu, const ExtentCase& c) {
    const bool render = stage == Stage::RenderSplat || stage == Stage::RenderMarch || stage == Stage::RenderLayers;
    // A larger call first on the same backend: its scratch buffers are then big enough already, and hold its values.
    ExtentCase primer = c;
    primer.grid = {c.grid.nx + 9, c.grid.ny + 5, c.grid.nz + 2};
    primer.width = c.width + 9, primer.height = c.height + 7;
    {
        SCOPED_TRACE("the larger call before: " + Describe(primer));
        if (render) {
            RunRenderExtentCase(stage, gpu, primer);
        } else {
            RunSimulationExtentCase(stage, gpu, primer);
        }
    }
    SCOPED_TRACE(Describe(c));
    if (render) return RunRenderExtentCase(stage, gpu, c);
    RunSimulationExtentCase(stage, gpu, c);
}

}  // namespace cb::extents
