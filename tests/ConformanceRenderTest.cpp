// Stage-isolated conformance of shade, shadow and the splat renderer, and the
// whole pipeline end to end (the fixture and the instantiation over every
// backend and size: ConformanceFixture.h, ConformanceTest.cpp).
#include <gtest/gtest.h>

#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "tests/ConformanceFixture.h"

namespace cb::conformance {
namespace {

// Test shading for every option and several suns: max |dT| <= 1e-5 for fp32,
// one stored code for fp16 and unorm8 (SPEC 6; a float difference can
// exceed 1/255 by an ulp where the codes differ by one).
TEST_P(Conformance, Shade) {
    if (auto why = SkipReason(Stage::Shade)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(21);
    std::vector<float> q(e.Count());
    for (float& v : q) v = rng.Below(3) == 0 ? float(rng.Below(65)) / 64.0f : 0.0f;
    auto refQ = test::MakeFilled(mCpu, BufferFormat::F32, e, q);
    auto gotQ = test::MakeFilled(*mBackend, BufferFormat::F32, e, q);
    auto refT = test::MakeBuffer(mCpu, BufferFormat::F32, e);
    auto gotT = test::MakeBuffer(*mBackend, BufferFormat::F32, e);
    const Vec3 suns[] = {
        {0, 0, 1}, SunDirection(0.44, 1.05), SunDirection(0.7853981633974483, 0.3), SunDirection(0.2, 3.5)};
    for (const Vec3& sun : suns)
        for (AttenuationKind att : {AttenuationKind::Beer, AttenuationKind::Thesis})
            for (SampleFilter filter : {SampleFilter::Bilinear, SampleFilter::Nearest})
                for (int f : {1, 2, 4})
                    for (StorageFormat storage : {StorageFormat::Fp32, StorageFormat::Fp16, StorageFormat::Unorm8})
                        for (bool scattering : {false, true}) {
                            ShadeParams p;
                            p.sun = sun;
                            p.attenuation = att;
                            p.filter = filter;
                            p.resolution = f;
                            p.storage = storage;
                            p.scattering = scattering;
                            p.sigma = 0.01f;
                            ASSERT_TRUE(mCpu.Shade(p, *refQ, *refT));
                            Status s = mBackend->Shade(p, *gotQ, *gotT);
                            ASSERT_TRUE(s.has_value()) << s.error().message;
                            const auto a = test::Read<float>(mCpu, *refT), b = test::Read<float>(*mBackend, *gotT);
                            // The stage's rule (StageDescriptorsTest pins it to SPEC 6): fp32 within 1e-5;
                            // fp16 and unorm8 within one stored code, compared as integers.
                            Scene scene;
                            scene.shade.storage = storage;
                            const CompareRule rule = Describe(Stage::Shade).rule(scene);
                            auto [worst, at] = WorstDifference(a, b);
                            const double tolerance = rule.tolerance;
                            if (rule.kind == CompareRule::Kind::Codes) {
                                std::vector<double> ca(a.size()), cb(b.size());
                                for (size_t v = 0; v < a.size(); ++v)
                                    ca[v] = StorageCode(storage, a[v]), cb[v] = StorageCode(storage, b[v]);
                                std::tie(worst, at) = WorstDifference(ca, cb);
                            }
                            ASSERT_LE(worst, tolerance)
                                << "sun (" << sun[0] << ", " << sun[1] << ", " << sun[2] << ") att " << int(att)
                                << " filter " << int(filter) << " f " << f << " storage " << int(storage)
                                << " scattering " << scattering << ": worst at " << Where(e, at) << ": cpu " << a[at]
                                << ", " << mBackend->Name() << " " << b[at];
                        }
}

// Test the ground shadow in every form, several suns: max |dG| <= 1e-5 (SPEC 7).
TEST_P(Conformance, Shadow) {
    if (auto why = SkipReason(Stage::Shadow)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(23);
    std::vector<float> D(size_t(e.nx) * e.ny);
    for (float& v : D) v = float(rng.Below(200)) / 64.0f;
    const Extent3 map{e.nx, e.ny, 1};
    auto refD = test::MakeFilled(mCpu, BufferFormat::F32, map, D);
    auto gotD = test::MakeFilled(*mBackend, BufferFormat::F32, map, D);
    auto refG = test::MakeBuffer(mCpu, BufferFormat::F32, map);
    auto gotG = test::MakeBuffer(*mBackend, BufferFormat::F32, map);
    for (const Vec3& sun : {Vec3{0, 0, 1}, SunDirection(0.5, 0.7), SunDirection(0.05, 2.0), SunDirection(-0.1, 0.0)})
        for (ShadowForm form : {ShadowForm::Beer, ShadowForm::Thesis, ShadowForm::Wang}) {
            ShadowParams p;
            p.sun = sun;
            p.form = form;
            p.coverage = 0.7f;  // wang: both of its terms active (C = D_w = 1 would be beer)
            p.densityFactor = 0.8f;
            p.nz = e.nz;
            ASSERT_TRUE(mCpu.Shadow(p, *refD, *refG));
            Status s = mBackend->Shadow(p, *gotD, *gotG);
            ASSERT_TRUE(s.has_value()) << s.error().message;
            const auto a = test::Read<float>(mCpu, *refG), b = test::Read<float>(*mBackend, *gotG);
            const auto [worst, at] = WorstDifference(a, b);
            EXPECT_LE(worst, Describe(Stage::Shadow).rule(Scene{}).tolerance)
                << "form " << int(form) << ": worst at " << Where(map, at) << ": cpu " << a[at] << ", "
                << mBackend->Name() << " " << b[at];
        }
}

// Test the splat renderer from four cameras (outside, inside, straight down,
// partly out of view), each with its own phase function (HG, Mie, Cornette-Shanks,
// Mie), with culling and skipping on, the last two cameras over
// the ground lit through a G (core/math/Ground.h): per channel |d| <= 2/255
// on 99.9 % of pixels and <= 8/255 everywhere (SPEC 8). A failure writes the
// difference image and names the worst pixel.
TEST_P(Conformance, RenderSplat) {
    if (auto why = SkipReason(Stage::RenderSplat)) GTEST_SKIP() << *why;
    const Extent3 e = Size();
    Pcg32 rng(29);
    std::vector<float> qPrev(e.Count()), qCur(e.Count()), T(e.Count());
    for (size_t v = 0; v < qPrev.size(); ++v) {
        const bool cloudy = (v / 61) % 4 == 0;
        qPrev[v] = cloudy ? float(rng.Below(65)) / 64.0f : 0.0f;
        qCur[v] = cloudy ? float(rng.Below(65)) / 64.0f : 0.0f;
        T[v] = float(rng.Below(256)) / 255.0f;
    }
    std::vector<float> G(size_t(e.nx) * e.ny);
    for (float& g : G) g = float(rng.Below(257)) / 256.0f;
    const float h = 50;
    const double cx = e.nx * h / 2, cy = e.ny * h / 2, cz = e.nz * h / 2;
    std::vector<CameraSettings> cameras(4);
    cameras[0].eye = {-cx, -cy, cz * 3};
    cameras[0].target = {cx, cy, cz};
    cameras[1].eye = {cx * 0.7, cy * 0.9, cz};
    cameras[1].target = {cx * 2, cy * 1.5, cz};
    cameras[2].eye = {cx, cy, cz * 8};
    cameras[2].target = {cx, cy, 0};
    cameras[3].eye = {-cx * 2, cy, cz};
    cameras[3].target = {cx * 4, cy * 3, cz};
    const uint32_t W = 96, H = 72;
    // A phase function per camera, so that every PhaseKind is drawn (Mie through phase_table.glsl's table).
    const PhaseParams phases[4] = {{PhaseKind::HenyeyGreenstein, 0.6f},
                                   {PhaseKind::Mie, 0},
                                   {PhaseKind::CornetteShanks, 0.7f},
                                   {PhaseKind::Mie, 0}};
    Backend* backends[2] = {&mCpu, mBackend.get()};
    const DensityParams density{8, 4, {}};
    for (size_t c = 0; c < cameras.size(); ++c) {
        std::vector<float> images[2];
        SplatStats stats[2];
        // Renders camera c on b into `rgb`, its stats into `st`.
        auto render = [&](Backend& b, std::vector<float>& rgb, SplatStats& st) {
            auto qp = test::MakeFilled(b, BufferFormat::F32, e, qPrev);
            auto qc = test::MakeFilled(b, BufferFormat::F32, e, qCur);
            auto t = test::MakeFilled(b, BufferFormat::F32, e, T);
            auto g = test::MakeFilled(b, BufferFormat::F32, {e.nx, e.ny, 1}, G);
            auto cld = test::MakeBuffer(b, BufferFormat::Bits, e);
            const Extent3 tiles{CeilDiv(e.nx, 8), CeilDiv(e.ny, 8), 1}, bands{tiles.nx, tiles.ny, CeilDiv(e.nz, 4)};
            std::unique_ptr<Buffer> occupancy[2][2];
            for (int step = 0; step < 2; ++step) {
                auto D = test::MakeBuffer(b, BufferFormat::F32, {e.nx, e.ny, 1});
                occupancy[step][0] = test::MakeBuffer(b, BufferFormat::U8, tiles);
                occupancy[step][1] = test::MakeBuffer(b, BufferFormat::U8, bands);
                DensityOutputs out{D.get(), occupancy[step][0].get(), occupancy[step][1].get(), 0};
                ASSERT_TRUE(b.Density(density, step == 0 ? *qp : *qc, cld.get(), out).has_value());
            }
            SplatParams p;
            p.camera = MakeCameraFrame(cameras[c], W, H);
            const SplatOrder order = MakeSplatOrder(p.camera, e, {0, 0, 0}, h);
            p.order = &order;
            p.voxelSize = h;
            p.splatDiameter = 1.5f * h;
            p.sun = SunDirection(0.5, 0.8);
            p.light.phase = phases[c];
            p.light.sunRadiance = {1.5f, 1.4f, 1.3f};
            p.light.ambient = {0.2f, 0.25f, 0.3f};
            p.background = {0.4f, 0.5f, 0.8f};
            p.tile = 8;
            p.band = 4;
            p.alpha = 0.4f;
            if (c >= 2) p.ground = {true, {0.4f, 0.35f, 0.3f}};
            auto image = test::MakeBuffer(b, BufferFormat::F32, {3, W, H});
            SplatInputs in{qp.get(),
                           qc.get(),
                           t.get(),
                           occupancy[0][0].get(),
                           occupancy[1][0].get(),
                           occupancy[0][1].get(),
                           occupancy[1][1].get()};
            in.G = p.ground.on ? g.get() : nullptr;
            Status s = b.RenderSplat(p, in, *image, &st);
            ASSERT_TRUE(s.has_value()) << s.error().message;
            rgb = test::Read<float>(b, *image);
        };
        for (int n = 0; n < 2; ++n) {
            render(*backends[n], images[n], stats[n]);
            if (HasFatalFailure()) return;
        }
#if CLOUDBENCH_HAVE_VK
        // vk's count and write passes take 1024 ranks an invocation on a CPU device and 32 on a GPU
        // (BackendVk::SetSplatChunkRanks): every chunk size gives the same bits.
        if (auto* vk = dynamic_cast<vk::BackendVk*>(mBackend.get())) {
            for (uint32_t ranks : {32u, 96u}) {
                vk->SetSplatChunkRanks(ranks);
                std::vector<float> rgb;
                SplatStats st;
                render(*vk, rgb, st);
                EXPECT_EQ(rgb, images[1]) << "camera " << c << ", " << ranks << " ranks a chunk";
                EXPECT_EQ(st.splats, stats[1].splats);
                EXPECT_EQ(st.voxelsVisited, stats[1].voxelsVisited);
                EXPECT_EQ(st.fragments, stats[1].fragments);
            }
            vk->SetSplatChunkRanks(0);
        }
#endif
        // The same voxels make splats everywhere, and every backend counts the
        // visited voxels and the fragments alike (GL: runs of visible boxes, and
        // a fragment query; vk: in its count pass).
        EXPECT_GT(stats[0].splats, 0u) << "camera " << c << " sees no splat: the test would prove nothing";
        EXPECT_EQ(stats[1].splats, stats[0].splats) << "camera " << c;
        EXPECT_EQ(stats[1].voxelsVisited, stats[0].voxelsVisited) << "camera " << c;
        EXPECT_EQ(stats[1].fragments, stats[0].fragments) << "camera " << c;
        const ImageComparison cmp = CompareImages(images[0], images[1], W, H).value();
        if (!cmp.Passes()) {
            const std::string path =
                ::testing::TempDir() + "/render_diff_" + mBackend->Name() + "_" + std::to_string(c) + ".exr";
            (void)WriteDifferenceImage(path, images[0], images[1], W, H);
            ADD_FAILURE() << "camera " << c << ": max error " << cmp.maxError << " at (" << cmp.worstX << ", "
                          << cmp.worstY << "), " << cmp.pixelsOverTolerance << " of " << cmp.pixels
                          << " pixels over 2/255, PSNR " << cmp.psnr << "; difference image: " << path;
        }
    }
}

// Every backend implements the thesis's splat pipeline; a lost stage would
// otherwise only turn its conformance tests into skips.
TEST_P(Conformance, ImplementsTheSplatPipeline) {
    if (std::get<1>(GetParam()).size.nx != 64) GTEST_SKIP() << "runs once per backend";
    for (Stage stage :
         {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade, Stage::Shadow, Stage::RenderSplat})
        EXPECT_TRUE(mBackend->Supports(stage)) << mBackend->Name() << " lacks " << StageName(stage);
    // The noise producer and the ray marcher are on every backend too.
    EXPECT_TRUE(mBackend->Supports(Stage::Noise)) << mBackend->Name() << " lacks noise";
    EXPECT_TRUE(mBackend->Supports(Stage::RenderMarch)) << mBackend->Name() << " lacks render_march";
}

// Test end to end: the simulation stages of ci-small for 15 steps, each backend
// on its own state. Where the region volumes are identical the automaton
// states must be identical too, step after step; where a region differs (SPEC
// allows |dR| <= 1), the states may drift and only the cover is compared, within
// 2 percentage points. (This is also the test of the RGBA8 automaton's
// chained steps, where each step starts from the state the last one left.)
TEST_P(Conformance, EndToEndSimulation) {
    for (Stage stage : {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density})
        if (!mBackend->Supports(stage))
            GTEST_SKIP() << "not implemented yet: " << mBackend->Name() << " has no " << StageName(stage) << " stage";
    if (std::get<1>(GetParam()).size.nx != 64) GTEST_SKIP() << "runs once per backend, on ci-small";
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json",
                           {{"stages", R"(["region", "ca", "smooth", "density"])"},
                            {"steps", "15"},
                            {"warmup_steps", "0"},
                            {"ca.wind_shift", "[[1, -1]]"}});
    ASSERT_TRUE(scene.has_value()) << scene.error().message;
    auto ref = Simulation::Create(*scene, mCpu);
    auto got = Simulation::Create(*scene, *mBackend);
    ASSERT_TRUE(ref.has_value() && got.has_value());
    bool regionsIdentical = true;
    const Extent3 e = scene->grid.size;
    for (uint32_t t = 0; t < scene->steps; ++t) {
        StepRecord a, b;
        ASSERT_TRUE((*ref)->Step(a).has_value());
        Status s = (*got)->Step(b);
        ASSERT_TRUE(s.has_value()) << s.error().message;
        // After Step, Region() holds R_t and Cld() the state t+1.
        regionsIdentical = regionsIdentical && test::Read<uint8_t>(mCpu, *(*ref)->Region()) ==
                                                   test::Read<uint8_t>(*mBackend, *(*got)->Region());
        if (regionsIdentical) {
            SCOPED_TRACE("step " + std::to_string(t));
            ExpectExact(test::Read<uint8_t>(mCpu, *(*ref)->Cld()), test::Read<uint8_t>(*mBackend, *(*got)->Cld()), e,
                        "cld");
            ExpectExact(test::Read<uint8_t>(mCpu, *(*ref)->Hum()), test::Read<uint8_t>(*mBackend, *(*got)->Hum()), e,
                        "hum");
            ExpectExact(test::Read<uint8_t>(mCpu, *(*ref)->Act()), test::Read<uint8_t>(*mBackend, *(*got)->Act()), e,
                        "act");
        }
        const double columns = double(e.nx) * e.ny;
        EXPECT_NEAR(*a.coveredColumns / columns, *b.coveredColumns / columns, regionsIdentical ? 0.0 : 0.02)
            << "step " << t;
    }
}

}  // namespace
}  // namespace cb::conformance
