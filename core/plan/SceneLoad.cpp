// Loading a scene: the JSON text, the overrides, every section read and
// checked on its own (core/scene/SceneReaders.h), then, in this one place, the
// checks that need more than one section or the pipeline: the stage graph's
// inputs (core/plan/StageGraph.h), what the renderers and the ground
// need, the optical depths, the lightning's and the sun's range over the run,
// the voxel count, and the memory the enabled stages need against what this
// process may use (core/plan/MemoryPlan.h). Every check reports into one
// list of "label: field: reason" lines, so a user sees all problems at once.
#include "core/plan/SceneLoad.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "core/base/PathPolicy.h"
#include "core/base/JsonDom.h"
#include "core/base/ProcessMemory.h"
#include "core/plan/MemoryPlan.h"
#include "core/plan/SceneSections.h"
#include "core/plan/StageGraph.h"
#include "core/scene/SceneReaders.h"
#include "core/scene/SceneValidator.h"

namespace cb {
namespace {

using scene_io::CheckAzimuth;
using scene_io::Describe;
using scene_io::FormatNumber;
using scene_io::IndexField;
using scene_io::Json;
using scene_io::JsonDom;
using scene_io::kMaxSingle;
using scene_io::kU32Max;
using scene_io::Quote;
using scene_io::Validator;

// Stages depend on resources, not on each other (core/plan/StageGraph.h): one line per stage and set
// of stages that could write what it lacks. Checked only on a clean list, so one typo does not cascade.
void CheckStageInputs(const StageSet& stages, Validator& check) {
    const std::vector<MissingInput> missing = MissingInputs(stages);
    for (size_t n = 0; n < missing.size();) {
        std::string resources, producers;
        size_t end = n;
        for (; end < missing.size() && missing[end].stage == missing[n].stage &&
               missing[end].producers == missing[n].producers;
             ++end)
            resources += (resources.empty() ? "" : " and ") + Quote(ResourceName(missing[end].resource));
        for (Stage p : missing[n].producers) producers += (producers.empty() ? "" : " or ") + Quote(StageName(p));
        check.Fail("stages", Quote(StageName(missing[n].stage)) + " needs " + resources +
                                 ", which no enabled stage writes (enable " + producers + ")");
        n = end;
    }
}

// The optical depths the stages derive from sigma, the voxel size and the sun (core/math/Shading.h), checked here in
// double where the single-precision kernels would overflow to infinity and turn 0 * inf into NaN: one shaded cell
// at q = 1, sigma h f (|s_w| >= 1/sqrt(3) divides it), and the beer shadow's factor sigma h / s_z.
void CheckOpticalDepths(const Scene& scene, Validator& check) {
    const double perCell = scene.shade.sigma * scene.grid.voxelSize * scene.shade.resolution;
    if (perCell > kMaxSingle) {
        check.Fail("shade.sigma",
                   "sigma * grid.voxel_size * shade.resolution (the optical depth of one cell) must be "
                   "at most 1e+30, got " +
                       FormatNumber(perCell));
        return;
    }
    // The lowest sun above the horizon over the run (a moving sun is evaluated at every step).
    float sz = scene.sun.Direction()[2];
    if (scene.sun.Moves()) {
        sz = 0;
        for (uint32_t t = 0; t < scene.steps; ++t)
            if (const float z = scene.sun.DirectionAt(t)[2]; z > 0 && (sz <= 0 || z < sz)) sz = z;
    }
    if (sz <= 0.0f) return;  // no sun, no shadow factor
    const double perD = scene.shade.sigma * scene.grid.voxelSize / double(sz);
    if (perD > kMaxSingle)
        check.Fail("shade.sigma",
                   "sigma * grid.voxel_size / sin(sun.elevation_deg) (the ground shadow's optical "
                   "depth per unit of D) must be at most 1e+30, got " +
                       FormatNumber(perD));
}

// The lightning's position in voxel edges, (position - origin) / h, as the kernel takes it (in float,
// core/math/March.h): at most 1e18 from the grid's corner on each axis. A sample p lies in the box (edges of at most
// 2^32 voxels), so |x_l - p|^2 <= 3 (1e18 + 2^32)^2 = 3e36 stays below float's 3.4e38; past about 1e19 it overflows to
// inf, and the light march toward the light then steps inf * 0 = NaN.
void CheckLightningPosition(const Scene& scene, Validator& check) {
    constexpr double kMaxVoxelEdges = 1e18;
    const LightningSettings& l = scene.lightning;
    if (!l.enabled) return;
    for (size_t c = 0; c < 3; ++c) {
        const double edges = (l.position[c] - scene.grid.origin[c]) / scene.grid.voxelSize;
        if (!(std::fabs(edges) <= kMaxVoxelEdges))
            check.Fail(IndexField("lightning.position", c),
                       "(position - grid.origin) / grid.voxel_size (the light's distance from the grid in voxel "
                       "edges) must be in [-1e+18, 1e+18], got " +
                           FormatNumber(edges));
    }
}

// A sun moving at a constant speed must stay within [-90, 90] degrees of elevation over the run's steps, and its
// azimuth within CheckAzimuth's bound (both are linear in the step: the last step is the farthest from step 0's).
void CheckSunSpeed(const Scene& scene, Validator& check) {
    const SunSettings& sun = scene.sun;
    if (!sun.path.empty()) return;
    const uint32_t last = scene.steps - 1;
    if (sun.elevationSpeedDeg != 0) {
        const double el = sun.ElevationAt(last);
        if (el < -90 || el > 90)
            check.Fail("sun.speed.elevation_deg", "the elevation reaches " + FormatNumber(el) +
                                                      " degrees at the last step (" + std::to_string(last) +
                                                      "), outside [-90, 90]");
    }
    if (sun.azimuthSpeedDeg != 0)
        CheckAzimuth(sun.AzimuthAt(last), "sun.speed.azimuth_deg", " at the last step (" + std::to_string(last) + ")",
                     check);
}

// Tiling repeats q with the grid's period: only a source that is periodic on that period may feed it, and only
// the renderers that read the volume periodically may run with it.
void CheckTiling(const Scene& scene, Validator& check) {
    if (!scene.grid.tiling) return;
    if (!scene.stages.Has(Stage::Noise) || scene.stages.Has(Stage::Ca) || scene.stages.Has(Stage::Smooth)) {
        check.Fail("grid.tiling",
                   "needs a source of q that repeats with the grid's period: the stage \"noise\" (the automaton's "
                   "volume does not wrap at the grid's sides)");
        return;
    }
    const NoiseDetail& detail = scene.noise.detail;
    if (detail.enabled && (scene.grid.size.nx % detail.size != 0 || scene.grid.size.ny % detail.size != 0))
        check.Fail("grid.tiling", "noise.detail.size (" + std::to_string(detail.size) +
                                      ") must divide grid.size's nx and ny (" + std::to_string(scene.grid.size.nx) +
                                      ", " + std::to_string(scene.grid.size.ny) +
                                      ") for the detail volume to repeat with the grid");
    // G is the shadow of one tile, computed over the grid's box; the ground would show it clamped past the box.
    if (scene.render.ground.on)
        check.Fail("render.ground",
                   "the ground shadow G covers one tile of grid.tiling and does not repeat; remove render.ground "
                   "or set grid.tiling to false");
    std::string honouring;  // the renderers that honour tiling, for the message
    for (Stage stage : kAllStages)
        if (const RendererDescriptor* r = Describe(stage).renderer; r && r->honoursTiling)
            honouring += (honouring.empty() ? "" : ", ") + std::string(StageName(stage));
    for (Stage stage : kAllStages)
        if (const RendererDescriptor* r = Describe(stage).renderer; r && !r->honoursTiling && scene.stages.Has(stage))
            check.Fail("grid.tiling",
                       Quote(StageName(stage)) +
                           " does not repeat the volume yet; the renderers that honour tiling: " + honouring);
}

// Relighting shades once, for the first step's sun: a renderer that does not relight would read that T as if it
// were shaded at its own step's sun.
// True when `stage` is an enabled renderer that relights in this scene (shades once, for the first step's sun).
bool RelightsHere(const Scene& scene, Stage stage) {
    const RendererDescriptor* r = Describe(stage).renderer;
    return r && r->relights && scene.stages.Has(stage) && r->relights(scene);
}

void CheckRelight(const Scene& scene, Validator& check) {
    for (Stage relighting : RendererStages()) {
        if (!RelightsHere(scene, relighting)) continue;
        const RendererDescriptor& r = *Describe(relighting).renderer;
        const std::string field =
            r.relightFields.empty() ? std::string(StageName(relighting)) : std::string(r.relightFields.front());
        for (Stage other : RendererStages())
            if (!Describe(other).renderer->relights && scene.stages.Has(other))
                check.Fail(field, Quote(StageName(relighting)) + " relights: it shades once, for the first step's sun, "
                                  "and " + Quote(StageName(other)) +
                                  " would light with that T at every step; run it without relighting");
    }
}

// What the enabled renderers ask of the stages upstream (Scene::needs).
Scene::RendererNeeds PlanRendererNeeds(const Scene& scene) {
    Scene::RendererNeeds needs;
    needs.shadeOnce = std::ranges::any_of(RendererStages(), [&](Stage s) { return RelightsHere(scene, s); });
    return needs;
}

void CheckAcrossSections(const Scene& scene, const scene_io::SectionsRead& sections, Validator& check) {
    if (sections.stageList) CheckStageInputs(scene.stages, check);
    // Every renderer draws one image per camera.
    for (Stage stage : kAllStages)
        if (Describe(stage).renderer && scene.stages.Has(stage) && sections.cameras && scene.render.cameras.empty())
            check.Fail("render.cameras", Quote(StageName(stage)) + " needs at least one camera");
    // Time-slicing spreads a step over the frames drawn between steps: without a renderer there are none.
    if (scene.render.slicesPerFrame > 0 && !RunsARenderer(scene.stages))
        check.Fail("render.slices_per_frame",
                   "time-slicing spreads a step over the frames drawn between steps, and "
                   "no renderer is enabled; enable " +
                       RendererNames(" or ") + ", or remove it");

    // The ground is lit through G: the stage that computes it must run.
    if (scene.render.ground.on && !scene.stages.Has(Stage::Shadow))
        check.Fail("render.ground",
                   "needs the stage \"shadow\", which computes the ground shadow G it is lit "
                   "through; enable it or remove render.ground");

    // The sky light is lit through T_sky: it shines iff the stage that shades toward it runs.
    if (scene.lighting.sky.on && !scene.stages.Has(Stage::ShadeSky))
        check.Fail("lighting.sky",
                   "needs the stage \"shade_sky\", which computes T_sky, the sky light's attenuation; enable it or "
                   "remove lighting.sky");
    if (!scene.lighting.sky.on && scene.stages.Has(Stage::ShadeSky))
        check.Fail("stages",
                   "\"shade_sky\" shades toward the sky light, and the scene has none (lighting.sky); add "
                   "lighting.sky or remove the stage");

    // Shafts of light are lit through the density map D: the stage that computes it must run.
    if (scene.lighting.shafts.on && !scene.stages.Has(Stage::Density))
        check.Fail("lighting.shafts",
                   "needs the stage \"density\", which computes the density map D the haze is lit through; enable it "
                   "or remove lighting.shafts");
    if (scene.lighting.shafts.on && scene.stages.Has(Stage::RenderMarch) && scene.march.reprojectionBlock > 1)
        check.Fail("lighting.shafts",
                   "a reprojected march frame (march.reprojection) starts from the previous frame's image, which "
                   "holds that frame's shafts, so they would add up frame after frame; remove one of the two");
    if (scene.lighting.shafts.on && !RunsARenderer(scene.stages))
        check.Fail("lighting.shafts",
                   "the shafts are added to a renderer's frame, and no renderer is enabled; enable " +
                       RendererNames(" or ") + ", or remove it");

    if (sections.steps) CheckSunSpeed(scene, check);
    CheckTiling(scene, check);
    CheckRelight(scene, check);
    CheckOpticalDepths(scene, check);
    CheckLightningPosition(scene, check);

    // Size checks, before anything grid-sized exists.
    if (!sections.gridSize) return;
    const Extent3& size = scene.grid.size;
    const uint64_t count = size.Count();
    if (count > kU32Max) {
        check.Fail("grid.size", std::string("[") + std::to_string(size.nx) + ", " + std::to_string(size.ny) + ", " +
                                    std::to_string(size.nz) + "] is " + std::to_string(count) +
                                    " voxels; the voxel index is 32-bit, so at most " + std::to_string(kU32Max));
        return;
    }
    // Against the fixed ceiling (machine, cgroup, RLIMIT_AS), not what happens to be free now: the backends check that.
    const uint64_t needed = EstimateSceneBytes(scene);
    if (std::optional<MemoryFigure> limit = ProcessMemoryLimit(); limit && needed > limit->bytes) {
        const std::string most =
            limit->source == "physical memory"
                ? "this machine's " + FormatGiB(limit->bytes) + " GiB"
                : "the " + FormatGiB(limit->bytes) + " GiB this process may use (" + limit->source + ")";
        check.Fail("grid.size", "the enabled stages need " + FormatGiB(needed) + " GiB, more than " + most);
    }
}

Result<Scene> ParseSceneChecked(const std::string& text, const std::string& label,
                                const std::vector<SceneOverride>& overrides) {
    Validator check(label);
    JsonDom dom = scene_io::ParseJsonDom(text);
    if (dom.failure) {
        check.FailWhole(scene_io::DescribeParseFailure(text, *dom.failure));
        return MakeError(check.Message());
    }
    Json& root = dom.root;
    for (const std::string& duplicate : dom.duplicates) check.Fail(duplicate, "duplicate field");
    if (!root.is_object()) {
        check.FailWhole("expected a JSON object at the top level, got " + Describe(root));
        return MakeError(check.Message());
    }
    for (const SceneOverride& item : overrides) scene_io::ApplyOverride(root, item, check);

    Scene scene;
    const scene_io::SectionsRead sections = scene_io::ReadSceneSections(root, label, check, scene);
    CheckAcrossSections(scene, sections, check);
    if (check.ErrorCount() > 0) return MakeError(check.Message());

    scene.needs = PlanRendererNeeds(scene);
    // One pair means "the same shift for every slice"; expanded only now that nz is known to be sane.
    if (scene.ca.windShift.size() == 1 && scene.grid.size.nz > 1)
        scene.ca.windShift.assign(scene.grid.size.nz, scene.ca.windShift[0]);
    return scene;
}

}  // namespace

Result<Scene> ParseScene(const std::string& text, const std::string& label,
                         const std::vector<SceneOverride>& overrides) {
    try {
        return ParseSceneChecked(text, label, overrides);
    } catch (const std::exception& e) {
        return MakeError(label + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(label + ": internal error while reading the scene");
    }
}

Result<Scene> LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides) {
    try {
        Result<std::string> text = ReadInputFile(path, kSceneInput);
        if (!text) return MakeError(text.error().message);
        Result<Scene> scene = ParseScene(*text, path, overrides);
        if (scene) scene->path = path;
        return scene;
    } catch (const std::exception& e) {
        return MakeError(path + ": internal error while reading the scene: " + e.what());
    } catch (...) {
        return MakeError(path + ": internal error while reading the scene");
    }
}

}  // namespace cb
