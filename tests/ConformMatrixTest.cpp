// conform --matrix and --vary: the built-in cases of a scene
// and their names, worked out by hand from scenes/ci-small.json; every option
// value covered; the cases of --vary; and the case in conform.csv, the
// baseline, the reruns' merge and the coverage summary.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/plan/SceneLoad.h"
#include "core/scene/SceneNames.h"
#include "harness/conform/Conform.h"
#include "harness/conform/ConformMatrix.h"

namespace cb {
namespace {

std::vector<std::string> MatrixCaseNames(const std::vector<ConformCase>& cases) {
    std::vector<std::string> names;
    for (const ConformCase& c : cases) names.push_back(c.name);
    return names;
}

Scene MatrixTestCiSmall() {
    auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    EXPECT_TRUE(scene.has_value()) << scene.error().message;
    return scene ? *scene : Scene{};
}

// Test the built-in cases of ci-small, by hand from scenes/ci-small.json: radius 1,
// beer, bilinear, resolution 1, fp32, no scattering, henyey-greenstein, shadow
// beer, culling and skipping on, no CA wind, and the sun at elevation 25°, azimuth
// 60°: s = (cos 25 cos 60, cos 25 sin 60, sin 25) = (0.453, 0.785, 0.423), so y is
// the principal axis and the sun cases are x and z. With gl compared in the packed
// layout, the last case is rgba8 on gl only.
TEST(ConformMatrix, CiSmallCasesByHand) {
    const Scene scene = MatrixTestCiSmall();
    const std::vector<ConformCase> cases = ConformMatrixCases(scene, gl::CaLayout::Packed, /*glCompared=*/true);
    const std::vector<std::string> expected = {
        "scene",
        "smooth.radius=0",
        "smooth.radius=2",
        "shade.attenuation=thesis",
        "shade.filter=nearest",
        "shade.resolution=2",
        "shade.resolution=4",
        "shade.storage=fp16",
        "shade.storage=unorm8",
        "shade.scattering.enabled=true",
        // henyey-greenstein with scattering is the case above, under its own name.
        "phase.function=none+shade.scattering.enabled=true",
        "phase.function=cornette-shanks+shade.scattering.enabled=true",
        "phase.function=mie+shade.scattering.enabled=true",
        "phase.function=dual-lobe+shade.scattering.enabled=true",
        "shadow.form=thesis",
        "shadow.form=wang",
        "render.culling=false",
        "render.skipping=false",
        "sun.elevation_deg=20+sun.azimuth_deg=10",
        "sun.elevation_deg=70+sun.azimuth_deg=30",
        "ca.wind_shift=[[1,-1]]",
        "gl-ca-layout=rgba8",
    };
    EXPECT_EQ(MatrixCaseNames(cases), expected);
    ASSERT_EQ(cases.size(), expected.size());
    EXPECT_TRUE(cases[0].overrides.empty());
    EXPECT_TRUE(cases[0].onlyBackends.empty());
    // The layout case: no scene override, gl only.
    EXPECT_TRUE(cases.back().overrides.empty());
    EXPECT_EQ(cases.back().glCaLayout, gl::CaLayout::Rgba8);
    EXPECT_EQ(cases.back().onlyBackends, std::vector<std::string>{"gl"});
    // A case's overrides are what its name says, in order.
    EXPECT_EQ(cases[11].overrides.size(), 2u);
    EXPECT_EQ(cases[11].overrides[0].path, "phase.function");
    EXPECT_EQ(cases[11].overrides[0].value, "cornette-shanks");
    EXPECT_EQ(cases[11].overrides[1].path, "shade.scattering.enabled");
    EXPECT_EQ(cases[11].overrides[1].value, "true");
    // Without gl there is no layout case; in the rgba8 layout the case is packed.
    EXPECT_EQ(ConformMatrixCases(scene, gl::CaLayout::Packed, false).size(), expected.size() - 1);
    EXPECT_EQ(ConformMatrixCases(scene, gl::CaLayout::Rgba8, true).back().name, "gl-ca-layout=packed");
}

// Test that every case's scene loads, and that over the scene and its cases every
// value of every option in the set is used at least once (the table of names is
// the reader's, so a new value added to it must be covered).
TEST(ConformMatrix, EveryValueCoveredAndEveryCaseLoads) {
    const Scene base = MatrixTestCiSmall();
    const std::vector<ConformCase> cases = ConformMatrixCases(base, gl::CaLayout::Packed, true);
    std::vector<Scene> scenes;
    for (const ConformCase& c : cases) {
        auto s = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json", c.overrides);
        ASSERT_TRUE(s.has_value()) << c.name << ": " << s.error().message;
        scenes.push_back(*s);
    }
    auto covered = [&](auto field, auto value) {
        return std::ranges::any_of(scenes, [&](const Scene& s) { return field(s) == value; });
    };
    for (int r : {0, 1, 2}) EXPECT_TRUE(covered([](const Scene& s) { return s.smooth.radius; }, r)) << r;
    for (int f : {1, 2, 4}) EXPECT_TRUE(covered([](const Scene& s) { return s.shade.resolution; }, f)) << f;
    for (const auto& e : kAttenuationKindNames)
        EXPECT_TRUE(covered([](const Scene& s) { return s.shade.attenuation; }, e.value)) << e.name;
    for (const auto& e : kSampleFilterNames)
        EXPECT_TRUE(covered([](const Scene& s) { return s.shade.filter; }, e.value)) << e.name;
    for (const auto& e : kStorageFormatNames)
        EXPECT_TRUE(covered([](const Scene& s) { return s.shade.storage; }, e.value)) << e.name;
    for (const auto& e : kShadowFormNames)
        EXPECT_TRUE(covered([](const Scene& s) { return s.shadow.form; }, e.value)) << e.name;
    // Every phase function reaches shade (with scattering on) and render_splat.
    for (const auto& e : kPhaseKindNames) {
        EXPECT_TRUE(std::ranges::any_of(scenes, [&](const Scene& s) {
            return s.phase.kind == e.value && s.shade.scattering && s.stages.Has(Stage::Shade);
        })) << e.name;
        EXPECT_TRUE(std::ranges::any_of(scenes, [&](const Scene& s) {
            return s.phase.kind == e.value && s.stages.Has(Stage::RenderSplat);
        })) << e.name;
    }
    for (bool b : {false, true}) {
        EXPECT_TRUE(covered([](const Scene& s) { return s.shade.scattering; }, b));
        EXPECT_TRUE(covered([](const Scene& s) { return s.splat.culling; }, b));
        EXPECT_TRUE(covered([](const Scene& s) { return s.splat.skipping; }, b));
        EXPECT_TRUE(covered([](const Scene& s) { return s.ca.HasWind(); }, b));
    }
    for (int w : {0, 1, 2})
        EXPECT_TRUE(covered([](const Scene& s) { return PrincipalAxis(s.sun.Direction()); }, w)) << w;
    // One option at a time: one override a case, but two for the sun's angles, and the phase's
    // scattering that lets shade see it; none for gl's layout.
    for (size_t k = 1; k < cases.size(); ++k) {
        const std::string& n = cases[k].name;
        const size_t want = cases[k].glCaLayout ? 0 : n.starts_with("sun.") ? 2 : n.starts_with("phase.") ? 2 : 1;
        EXPECT_EQ(cases[k].overrides.size(), want) << n;
    }
}

// Test that a case equal to the scene is dropped, and only the stages the scene runs get cases:
// without shade, the phase reaches render_splat alone (no scattering override).
TEST(ConformMatrix, OnlyWhatTheSceneRuns) {
    Scene scene = MatrixTestCiSmall();
    scene.stages = StageSet{Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::RenderSplat};
    scene.smooth.radius = 2;
    scene.splat.culling = false;
    scene.phase.kind = PhaseKind::CornetteShanks;
    scene.ca.windShift = {{1, 0}};
    const std::vector<std::string> expected = {
        "scene",
        "smooth.radius=0",
        "smooth.radius=1",
        "phase.function=none",
        "phase.function=henyey-greenstein",
        "phase.function=mie",
        "phase.function=dual-lobe",
        "render.culling=true",
        "render.skipping=false",
        "ca.wind_shift=[]",
    };
    EXPECT_EQ(MatrixCaseNames(ConformMatrixCases(scene, gl::CaLayout::Packed, false)), expected);
}

// Test the sun cases at each principal axis of the scene, and none for a moving sun.
TEST(ConformMatrix, SunCasesOnTheOtherAxes) {
    Scene scene;
    scene.stages = StageSet{Stage::Shade};
    auto sunCases = [&] {
        std::vector<std::string> out;
        for (const ConformCase& c : ConformMatrixCases(scene, gl::CaLayout::Packed, false))
            if (c.name.starts_with("sun.")) out.push_back(c.name);
        return out;
    };
    scene.sun.elevationDeg = 10, scene.sun.azimuthDeg = 0;  // s = (0.985, 0, 0.174): x
    EXPECT_EQ(sunCases(), (std::vector<std::string>{"sun.elevation_deg=20+sun.azimuth_deg=80",
                                                    "sun.elevation_deg=70+sun.azimuth_deg=30"}));
    scene.sun.elevationDeg = 80;  // z
    EXPECT_EQ(sunCases(), (std::vector<std::string>{"sun.elevation_deg=20+sun.azimuth_deg=10",
                                                    "sun.elevation_deg=20+sun.azimuth_deg=80"}));
    scene.sun.azimuthSpeedDeg = 1;
    EXPECT_TRUE(sunCases().empty());
}

// Test the names, the folders and --vary's cartesian product (the last axis fastest, as sweep's).
TEST(ConformMatrix, NamesFoldersAndVary) {
    EXPECT_EQ(ConformCaseName({}, std::nullopt), "scene");
    EXPECT_EQ(ConformCaseName({{"a.b", "1"}, {"c", "x"}}, gl::CaLayout::Rgba8), "a.b=1+c=x+gl-ca-layout=rgba8");
    EXPECT_EQ(ConformCaseFolder("stages=[\"region\",\"ca\"]+x/y=1"), "stages=__region___ca__+x_y=1");
    const std::vector<ConformCase> cases =
        ConformVaryCases({{"smooth.radius", {"0", "2"}}, {"shade.storage", {"fp16", "unorm8"}}});
    EXPECT_EQ(MatrixCaseNames(cases),
              (std::vector<std::string>{"smooth.radius=0+shade.storage=fp16", "smooth.radius=0+shade.storage=unorm8",
                                        "smooth.radius=2+shade.storage=fp16", "smooth.radius=2+shade.storage=unorm8"}));
    EXPECT_EQ(cases[2].overrides[0].value, "2");
    EXPECT_EQ(cases[2].overrides[1].value, "fp16");
    EXPECT_TRUE(ConformVaryCases({}).empty());
}

ConformRow MatrixCaseRow(const std::string& caseName, const std::string& stage, const std::string& backend,
                         const std::string& status) {
    ConformRow r;
    r.caseName = caseName;
    r.stage = stage;
    r.backend = backend;
    r.status = status;
    return r;
}

// Test conform.csv with cases: the case first on every line; read back as a
// baseline it lists each failing row of its case only.
TEST(ConformMatrix, CsvAndBaselinePerCase) {
    std::vector<ConformRow> rows = {MatrixCaseRow("scene", "shade", "vk", "pass"),
                                    MatrixCaseRow("shade.storage=fp16", "shade", "vk", "fail"),
                                    MatrixCaseRow("stages=[\"a\",\"b\"]", "smooth", "gl", "fail")};
    rows[1].rule = "|dcode| <= 1";
    EXPECT_EQ(ConformCsv(rows),
              "case,stage,backend,status,rule,worst,tolerance,detail\n"
              "scene,shade,vk,pass,,0,0,\n"
              "shade.storage=fp16,shade,vk,fail,|dcode| <= 1,0,0,\n"
              "\"stages=[\"\"a\"\",\"\"b\"\"]\",smooth,gl,fail,,0,0,\n");
    auto b = ParseConformBaseline("conform.csv", ConformCsv(rows));
    ASSERT_TRUE(b.has_value()) << b.error().message;
    EXPECT_EQ(b->knownFailures.size(), 2u);
    EXPECT_TRUE(b->Lists("shade.storage=fp16", "shade", "vk"));
    EXPECT_TRUE(b->Lists("stages=[\"a\",\"b\"]", "smooth", "gl"));
    EXPECT_FALSE(b->Lists("scene", "shade", "vk"));
    EXPECT_FALSE(b->Lists("shade", "vk"));  // no case: a run without --matrix
    // Applied: the listed failure is expected, the same stage in another case still fails.
    std::vector<ConformRow> next = {MatrixCaseRow("shade.storage=fp16", "shade", "vk", "fail"),
                                    MatrixCaseRow("shade.storage=unorm8", "shade", "vk", "fail"),
                                    MatrixCaseRow("stages=[\"a\",\"b\"]", "smooth", "gl", "pass")};
    ApplyBaseline(next, *b);
    EXPECT_EQ(next[0].status, "expected-fail");
    EXPECT_EQ(next[1].status, "fail");
    EXPECT_EQ(next[2].status, "unexpected-pass");
    EXPECT_EQ(ConformExitCode(next), 5);
    // A hand-written baseline: the header switches to cases and back; a case line without its status is refused.
    auto mixed = ParseConformBaseline("b.txt",
                                      "shade,vk,fail\ncase,stage,backend,status\n x , smooth , gl , fail\n"
                                      "stage,backend,status\nca,gl,fail\n");
    ASSERT_TRUE(mixed.has_value()) << mixed.error().message;
    EXPECT_TRUE(mixed->Lists("shade", "vk"));
    EXPECT_TRUE(mixed->Lists("x", "smooth", "gl"));
    EXPECT_TRUE(mixed->Lists("ca", "gl"));
    EXPECT_EQ(mixed->knownFailures.size(), 3u);
    auto bad = ParseConformBaseline("b.txt", "case,stage,backend,status\nx,smooth,gl\n");
    ASSERT_FALSE(bad.has_value());
    EXPECT_EQ(bad.error().message, "b.txt: line 2: expected case,stage,backend,status");
    auto twice = ParseConformBaseline("b.txt", "case,stage,backend,status\nx,smooth,gl,fail\nx,smooth,gl,fail\n");
    ASSERT_FALSE(twice.has_value());
    EXPECT_EQ(twice.error().message, "b.txt: line 3: x,smooth,gl is listed twice");
}

// Test that a rerun is merged into the row of its own case only.
TEST(ConformMatrix, RerunMergesWithinTheCase) {
    std::vector<ConformRow> first = {MatrixCaseRow("a", "shade", "vk", "fail"),
                                     MatrixCaseRow("b", "shade", "vk", "fail")};
    MergeRerun(first, {MatrixCaseRow("b", "shade", "vk", "pass"), MatrixCaseRow("a", "shade", "vk", "fail")}, 1);
    EXPECT_EQ(first[0].status, "fail");
    EXPECT_EQ(first[1].status, "flaky");
    EXPECT_EQ(first[1].caseName, "b");
}

// Test the coverage over cases: each option's values, each with the backends that compared it.
TEST(ConformMatrix, CoverageOverCases) {
    Scene hg, cs;
    hg.shade.scattering = cs.shade.scattering = true;
    hg.phase.kind = PhaseKind::HenyeyGreenstein;
    cs.phase.kind = PhaseKind::CornetteShanks;
    const std::vector<ConformCaseScene> scenes = {
        {"scene", &hg, "packed"}, {"cs", &cs, "packed"}, {"layout", &hg, "rgba8"}};
    const std::vector<ConformRow> rows = {
        MatrixCaseRow("scene", "shade", "vk", "pass"),     MatrixCaseRow("scene", "shade", "gl", "pass"),
        MatrixCaseRow("cs", "shade", "vk", "fail"),        MatrixCaseRow("cs", "shade", "gl", "skipped"),
        MatrixCaseRow("cs", "render_splat", "gl", "pass"), MatrixCaseRow("scene", "ca", "gl", "pass"),
        MatrixCaseRow("layout", "ca", "gl", "pass"),       MatrixCaseRow("scene", "ca", "vk", "pass"),
        MatrixCaseRow("layout", "(all)", "gl", "crashed")};
    const nlohmann::json c = ConformMatrixCoverage(scenes, rows);
    EXPECT_EQ(c["shade"]["options"]["phase"],
              nlohmann::json({{"henyey-greenstein", nlohmann::json::array({"vk", "gl"})},
                              {"cornette-shanks", nlohmann::json::array({"vk"})}}));
    EXPECT_EQ(c["shade"]["cases"], nlohmann::json({"scene", "cs"}));
    // Scene's default sun: elevation 40, azimuth 30: (0.663, 0.383, 0.643), x by a hair over z.
    EXPECT_EQ(c["shade"]["options"]["principal_axis"], nlohmann::json({{"x", nlohmann::json::array({"vk", "gl"})}}));
    EXPECT_EQ(c["shade"]["compared_on"], nlohmann::json({"vk", "gl"}));
    EXPECT_EQ(c["render_splat"]["options"]["phase"],
              nlohmann::json({{"cornette-shanks", nlohmann::json::array({"gl"})}}));
    EXPECT_EQ(c["ca"]["options"]["gl_ca_layout"],
              nlohmann::json({{"packed", nlohmann::json::array({"gl"})}, {"rgba8", nlohmann::json::array({"gl"})}}));
    EXPECT_EQ(c["ca"]["options"]["wind"], nlohmann::json({{"false", nlohmann::json::array({"gl", "vk"})}}));
    EXPECT_FALSE(c.contains("(all)"));
}

}  // namespace
}  // namespace cb
