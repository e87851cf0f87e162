#include "harness/conform/ConformMatrix.h"

#include <algorithm>

#include "core/math/Shading.h"
#include "core/scene/SceneNames.h"

namespace cb {
namespace {

std::string BoolText(bool b) { return b ? "true" : "false"; }

// One candidate case of the built-in set: its overrides, before those equal to the scene's are dropped.
struct Candidate {
    std::vector<SceneOverride> overrides;
    std::optional<gl::CaLayout> glCaLayout;
    std::vector<std::string> onlyBackends;
};

// The stages of `scene` less `drop`, as a JSON list for --set stages=...
std::string StagesWithout(const Scene& scene, Stage drop) {
    std::string list;
    for (Stage s : kAllStages)
        if (scene.stages.Has(s) && s != drop) list += (list.empty() ? "\"" : ",\"") + std::string(StageName(s)) + "\"";
    return "[" + list + "]";
}

}  // namespace

std::optional<std::string> ConformSceneValue(const Scene& scene, const std::string& path) {
    if (path == "smooth.radius") return std::to_string(scene.smooth.radius);
    if (path == "shade.attenuation") return std::string(AttenuationKindName(scene.shade.attenuation));
    if (path == "shade.filter") return std::string(SampleFilterName(scene.shade.filter));
    if (path == "shade.resolution") return std::to_string(scene.shade.resolution);
    if (path == "shade.storage") return std::string(StorageFormatName(scene.shade.storage));
    if (path == "shade.scattering.enabled") return BoolText(scene.shade.scattering);
    if (path == "phase.function") return std::string(PhaseKindName(scene.phase.kind));
    if (path == "shadow.form") return std::string(ShadowFormName(scene.shadow.form));
    if (path == "render.culling") return BoolText(scene.splat.culling);
    if (path == "render.skipping") return BoolText(scene.splat.skipping);
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
    const bool shade = stages.Has(Stage::Shade), splat = stages.Has(Stage::RenderSplat);
    std::vector<Candidate> candidates;
    auto each = [&](bool when, const std::string& path, std::initializer_list<std::string_view> values) {
        if (!when) return;
        for (std::string_view v : values) candidates.push_back({{{path, std::string(v)}}, {}, {}});
    };
    auto names = [](const auto& table) {
        std::vector<std::string_view> out;
        for (const auto& entry : table) out.push_back(entry.name);
        return out;
    };
    auto eachNamed = [&](bool when, const std::string& path, const std::vector<std::string_view>& values) {
        if (!when) return;
        for (std::string_view v : values) candidates.push_back({{{path, std::string(v)}}, {}, {}});
    };
    each(stages.Has(Stage::Smooth), "smooth.radius", {"0", "1", "2"});
    eachNamed(shade, "shade.attenuation", names(kAttenuationKindNames));
    eachNamed(shade, "shade.filter", names(kSampleFilterNames));
    each(shade, "shade.resolution", {"1", "2", "4"});
    eachNamed(shade, "shade.storage", names(kStorageFormatNames));
    each(shade, "shade.scattering.enabled", {"false", "true"});
    // The phase function: with scattering on when the scene shades, so that shade compares it too.
    if (shade || splat)
        for (const auto& [name, kind] : kPhaseKindNames) {
            Candidate c{{{"phase.function", std::string(name)}}, {}, {}};
            if (shade) c.overrides.push_back({"shade.scattering.enabled", "true"});
            if (kind == PhaseKind::Mie) {
                // render_splat on gl and vk refuses a Mie scene (docs/scenes.md, issue 14): compared without it,
                // and only where shade (P(0) of the table) still sees it.
                if (!shade) continue;
                if (splat) c.overrides.push_back({"stages", StagesWithout(scene, Stage::RenderSplat)});
            }
            candidates.push_back(std::move(c));
        }
    eachNamed(stages.Has(Stage::Shadow), "shadow.form", names(kShadowFormNames));
    each(splat, "render.culling", {"true", "false"});
    each(splat, "render.skipping", {"true", "false"});
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
