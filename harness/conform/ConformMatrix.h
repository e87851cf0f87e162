// `cloudbench conform --matrix` and `--vary`: the cases a conformance run
// compares, each the scene with a few overrides (and, for gl's automaton
// layout, a backend option), named by them. docs/cli.md lists the built-in set
// and docs/testing.md ("Conformance over the option matrix") why it is
// one-at-a-time from the scene's own settings rather than a product.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/scene/Scene.h"
#include "harness/run/VaryAxes.h"
#include "registry/Registry.h"

namespace cb {

struct ConformCase {
    // "scene" for the scene's own settings, else ConformCaseName(overrides, glCaLayout).
    std::string name;
    std::vector<SceneOverride> overrides;    // applied after --set
    std::optional<gl::CaLayout> glCaLayout;  // --gl-ca-layout for this case
    std::vector<std::string> onlyBackends;   // empty: every backend compared; else only these
};

inline constexpr const char* kSceneCaseName = "scene";

// The overrides as PATH=VALUE joined by '+', then "gl-ca-layout=NAME" when a
// layout is given; "scene" when there is neither.
std::string ConformCaseName(const std::vector<SceneOverride>& overrides, std::optional<gl::CaLayout> glCaLayout);

// The built-in option set (--matrix): the case "scene", then, one option at a
// time from the scene's own settings, every value of every option below that
// the scene does not already use, for the stages the scene runs: each stage's
// choice settings in CB_STAGES order (its descriptor's `choices`: smooth.radius;
// shade.attenuation, filter, resolution, storage, scattering.enabled; shadow.form;
// render.culling, render.skipping), with, after shade's, phase.function when shade runs or a
//   renderer whose descriptor asks for it (conformVariesPhase; with scattering on when the scene
//   shades, so that shade and the renderer both see it); the sun on each principal axis (a fixed
//   sun only); ca.wind_shift (on when the scene has none, off otherwise); and,
//   when `glCompared`, gl's other automaton layout (a case for gl only).
// A case whose overrides all equal the scene's values is dropped (the case
// "scene" covers it), and so is a second case of the same name.
std::vector<ConformCase> ConformMatrixCases(const Scene& scene, gl::CaLayout sceneLayout, bool glCompared);

// The cartesian product of --vary PATH=V1,V2 axes as cases, in sweep's order
// (the last axis fastest); no axes: none.
std::vector<ConformCase> ConformVaryCases(const std::vector<SweepAxis>& axes);

// The scene's value of a path the built-in set varies, as --set writes it
// ("2", "true", "fp16", ...); nullopt for any other path.
std::optional<std::string> ConformSceneValue(const Scene& scene, const std::string& path);

// A folder name for a case's outputs (difference images): the name with every
// character outside [A-Za-z0-9._=+-] replaced by '_'.
std::string ConformCaseFolder(const std::string& name);

}  // namespace cb
