#include "core/plan/SceneSections.h"

#include <filesystem>
#include <optional>
#include <string_view>

#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"
#include "core/stages/ca/Ca.h"
#include "core/stages/density/Density.h"
#include "core/stages/noise/Noise.h"
#include "core/stages/region/Region.h"
#include "core/stages/render_layers/RenderLayers.h"
#include "core/stages/render_march/RenderMarch.h"
#include "core/stages/render_splat/RenderSplat.h"
#include "core/stages/shade/Shade.h"
#include "core/stages/shadow/Shadow.h"
#include "core/stages/smooth/Smooth.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kTopKeys[] = {
    "name", "description", "grid",  "steps", "warmup_steps", "stages", "ca",    "ellipsoids", "smooth", "density",
    "sun",  "lighting",    "phase", "shade", "shadow",       "render", "march", "lightning",  "noise",  "layers"};

}  // namespace

SectionsRead ReadSceneSections(const Json& root, const std::string& label, Validator& check, Scene& scene) {
    SectionsRead sections;
    check.CheckKeys(root, "", kTopKeys);

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
                                               std::to_string(scene.warmupSteps));
        }
    }

    sections.stageList = ReadStages(root, check, scene.stages);
    ReadCa(root, check, sizeOk ? std::optional(scene.grid.size.nz) : std::nullopt, scene.ca);

    // The ellipsoid seed follows ca.seed unless given.
    scene.ellipsoids.seed = scene.ca.seed;
    ReadEllipsoids(root, check, scene.ellipsoids);

    ReadSmooth(root, check, scene.smooth);
    ReadDensity(root, check, scene.density, sizeOk ? &scene.grid.size : nullptr);

    ReadSun(root, check, scene.sun);
    ReadLighting(root, check, scene.lighting);
    ReadPhase(root, check, scene.phase);
    ReadShade(root, check, scene.shade);
    ReadShadow(root, check, scene.shadow);
    sections.cameras = ReadRender(root, check, scene.render);
    ReadSplat(root, check, scene.splat);
    ReadMarch(root, check, scene.stages, scene.march);
    ReadLightning(root, check, scene.lightning);
    ReadNoise(root, check, scene.noise);
    ReadLayers(root, check, sizeOk ? std::optional(scene.grid.size.nz) : std::nullopt, scene.layers);
    return sections;
}

}  // namespace cb::scene_io
