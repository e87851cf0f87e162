#include "harness/conform/ConformMatrix.h"

#include <algorithm>

#include "core/math/Shading.h"
#include "core/plan/StageGraph.h"
#include "core/scene/SceneNames.h"
#include "core/stages/shade/Shade.h"

namespace cb {
namespace {

// One candidate case of the built-in set: its overrides, before those equal to the scene's are dropped.
struct Candidate {
    std::vector<SceneOverride> overrides;
    std::optional<gl::CaLayout> glCaLayout;
    std::vector<std::string> onlyBackends;
};

}  // namespace

std::optional<std::string> ConformSceneValue(const Scene& scene, const std::string& path) {
    for (Stage stage : kAllStages)
        for (const ChoiceSetting& choice : Describe(stage).choices)
            if (choice.path == path) return choice.current(scene);
    if (path == "phase.function") return std::string(PhaseKindName(scene.phase.kind));
    return std::nullopt;
}

std::string ConformCaseName(const std::vector<SceneOverride>& overrides, std::optional<gl::CaLayout> glCaLayout) {
    std::string name;
    for (const SceneOverride& o : overrides) name += (name.empty() ? "" : "+") + o.path + "=" + o.value;
    if (glCaLayout)
        name += (name.empty() ? "" : "+") + std::string("gl-ca-layout=") + std::string(gl::CaLayoutName(*glCaLayout));
    return name.empty() ? kSceneCaseName : name;
}

std::vector<ConformCase> ConformMatrixCases(const Scene& scene, gl::CaLayout sceneLayout, bool glCompared) {
    const StageSet& stages = scene.stages;
    const bool shade = stages.Has(Stage::Shade);
    const bool rendererVariesPhase = std::ranges::any_of(
        RendererStages(), [&](Stage s) { return stages.Has(s) && Describe(s).renderer->conformVariesPhase; });
    std::vector<Candidate> candidates;
    // The phase function: with scattering on when the scene shades, so that shade compares it too.
    auto eachPhase = [&] {
        if (!shade && !rendererVariesPhase) return;
        for (const auto& [name, kind] : kPhaseKindNames) {
            Candidate c{{{"phase.function", std::string(name)}}, {}, {}};
            if (shade) c.overrides.push_back({std::string(ShadeScatteringSetting().path), "true"});
            candidates.push_back(std::move(c));
        }
    };
    // Every value of each enabled stage's choice settings (its descriptor's), the phase function after shade's.
    for (Stage stage : kAllStages) {
        if (stages.Has(stage))
            for (const ChoiceSetting& choice : Describe(stage).choices)
                for (std::string& value : choice.values())
                    candidates.push_back({{{std::string(choice.path), std::move(value)}}, {}, {}});
        if (stage == Stage::Shade) eachPhase();
    }
    // The sun on each principal axis other than the scene's (a fixed sun; shade marches along that axis).
    if (shade && !scene.sun.Moves()) {
        const int axis = PrincipalAxis(scene.sun.Direction());
        // x: (0.925, 0.163, 0.342); y: (0.163, 0.925, 0.342); z: (0.296, 0.171, 0.940).
        const char* sun[3][2] = {{"20", "10"}, {"20", "80"}, {"70", "30"}};
        for (int w = 0; w < 3; ++w)
            if (w != axis)
                candidates.push_back({{{"sun.elevation_deg", sun[w][0]}, {"sun.azimuth_deg", sun[w][1]}}, {}, {}});
    }
    // The automaton's wind shift (advection): on when the scene has none, off otherwise.
    if (stages.Has(Stage::Ca))
        candidates.push_back({{{"ca.wind_shift", scene.ca.HasWind() ? "[]" : "[[1,-1]]"}}, {}, {}});
    // gl's other automaton layout, on gl only.
    if (stages.Has(Stage::Ca) && glCompared)
        for (const auto& [name, layout] : gl::kCaLayoutNames)
            if (layout != sceneLayout) candidates.push_back({{}, layout, {"gl"}});

    std::vector<ConformCase> cases = {{kSceneCaseName, {}, std::nullopt, {}}};
    for (Candidate& c : candidates) {
        std::erase_if(c.overrides, [&](const SceneOverride& o) { return ConformSceneValue(scene, o.path) == o.value; });
        if (c.overrides.empty() && !c.glCaLayout) continue;
        std::string name = ConformCaseName(c.overrides, c.glCaLayout);
        if (std::ranges::any_of(cases, [&](const ConformCase& k) { return k.name == name; })) continue;
        cases.push_back({std::move(name), std::move(c.overrides), c.glCaLayout, std::move(c.onlyBackends)});
    }
    return cases;
}

std::vector<ConformCase> ConformVaryCases(const std::vector<SweepAxis>& axes) {
    if (axes.empty()) return {};
    std::vector<ConformCase> cases;
    for (auto& p : VaryPoints(axes))
        cases.push_back({ConformCaseName(p, std::nullopt), std::move(p), std::nullopt, {}});
    return cases;
}

std::string ConformCaseFolder(const std::string& name) {
    std::string folder = name;
    for (char& ch : folder) {
        const bool ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') || ch == '.' ||
                        ch == '_' || ch == '=' || ch == '+' || ch == '-';
        if (!ok) ch = '_';
    }
    return folder;
}

}  // namespace cb
