#include "core/plan/SceneSections.h"

#include <filesystem>
#include <string_view>
#include <vector>

#include "core/pipeline/LightTerms.h"
#include "core/plan/StageGraph.h"
#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

// The top-level keys of the sections every stage shares; each stage's descriptor adds its own (sceneKeys).
constexpr std::string_view kSharedKeys[] = {"name", "description", "grid",      "steps", "warmup_steps", "stages",
                                            "sun",  "lighting",    "lightning", "phase", "render"};

std::vector<std::string_view> TopKeys() {
    std::vector<std::string_view> keys(std::begin(kSharedKeys), std::end(kSharedKeys));
    for (Stage stage : kAllStages)
        for (std::string_view key : Describe(stage).sceneKeys) keys.push_back(key);
    return keys;
}

}  // namespace

SectionsRead ReadSceneSections(const Json& root, const std::string& label, Validator& check, Scene& scene) {
    SectionsRead sections;
    check.CheckKeys(root, "", TopKeys());

    // The name becomes the folder out/<name>: it follows kPathNameRule, and so must the file stem it defaults to.
    if (const Json* v = Validator::Find(root, "name")) {
        if (auto s = check.PathName(*v, "name")) scene.name = *s;
    } else {
        scene.name = std::filesystem::path(label).stem().string();
        if (!IsPathName(scene.name))
            check.Fail("name", "the default name " + QuoteShown(scene.name) + " (the file name) " +
                                   std::string(kPathNameRule) + "; set \"name\" in the file");
    }
    if (const Json* v = Validator::Find(root, "description")) check.String(*v, "description");

    sections.gridSize = ReadGrid(root, check, scene.grid);
    const bool sizeOk = sections.gridSize;

    bool stepsOk = true;
    if (const Json* v = Validator::Find(root, "steps")) {
        auto n = check.Integer(*v, "steps", 1, 10000000);
        if (n) scene.steps = uint32_t(*n);
        stepsOk = n.has_value();
        sections.steps = stepsOk;
    }
    if (const Json* v = Validator::Find(root, "warmup_steps")) {
        if (auto n = check.Integer(*v, "warmup_steps", 0, kU32Max)) {
            scene.warmupSteps = uint32_t(*n);
            if (stepsOk && scene.warmupSteps >= scene.steps)
                check.Fail("warmup_steps", "must be < steps (" + std::to_string(scene.steps) + "), got " +
                                               std::to_string(scene.warmupSteps) +
                                               " (more steps, or fewer warm-up steps: --set warmup_steps=N)");
        }
    }

    sections.stageList = ReadStages(root, check, scene.stages);
    ReadSun(root, check, scene.sun);
    ReadLighting(root, check, scene.lighting);
    ReadLightning(root, check, scene.lightning);
    ReadPhase(root, check, scene.phase);
    // Mie's table has no eccentricity for the octaves to scale.
    if (scene.lighting.octaves.count > 1 && scene.phase.kind == PhaseKind::Mie &&
        scene.lighting.octaves.eccentricity != 1)
        check.Fail("lighting.octaves.eccentricity",
                   "must be 1 with phase.function \"mie\" (the table's shape cannot be scaled), got " +
                       FormatNumber(scene.lighting.octaves.eccentricity));
    sections.cameras = ReadRender(root, check, scene.render);

    // Each stage's own sections, by its descriptor's reader, in CB_STAGES order (also for stages not enabled).
    for (Stage stage : kAllStages)
        if (auto read = Describe(stage).readSettings) read(root, check, sizeOk ? &scene.grid.size : nullptr, scene);

    // The ellipsoids' seed follows ca.seed unless the file gives one.
    const Json* ellipsoids = Validator::Find(root, "ellipsoids");
    if (!(ellipsoids && ellipsoids->is_object() && Validator::Find(*ellipsoids, "seed")))
        scene.ellipsoids.seed = scene.ca.seed;
    return sections;
}

}  // namespace cb::scene_io
