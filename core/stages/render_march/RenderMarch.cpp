#include "core/stages/render_march/RenderMarch.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <limits>
#include <memory>
#include <string_view>

#include "core/base/NamedValues.h"
#include "core/pipeline/LightTerms.h"
#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"
#include "core/stages/shade/Shade.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kMarchKeys[] = {"step",    "adaptive", "jitter",   "light",        "light_steps", "powder",
                                           "epsilon", "skipping", "exposure", "reprojection", "tone_map"};
constexpr std::string_view kAdaptiveKeys[] = {"enabled", "kappa", "start"};
constexpr std::string_view kPowderKeys[] = {"enabled", "c"};
constexpr std::string_view kSkippingKeys[] = {"enabled", "brick"};
constexpr std::string_view kReprojectionKeys[] = {"block"};

constexpr std::array<NamedValue<MarchLightSource>, 2> kMarchLightNames{{
    {"shade", MarchLightSource::Shade},
    {"march", MarchLightSource::March},
}};

// The smallest step: a ray across a 16384-voxel box then takes about 1.6e6 samples, not unbounded work.
constexpr double kMinMarchStep = 0.01;

}  // namespace

void ReadMarch(const Json& root, Validator& check, const StageSet& stages, MarchSettings& march) {
    const Json* section = check.Section(root, "", "march", kMarchKeys);
    if (section) {
        auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
        if (const Json* v = find("step")) {
            if (auto d = check.Number(*v, "march.step", Range{.lo = kMinMarchStep, .hi = 1e6})) march.step = *d;
        }
        if (const Json* adaptive = check.Section(*section, "march", "adaptive", kAdaptiveKeys)) {
            if (const Json* v = Validator::Find(*adaptive, "enabled")) {
                if (auto b = check.Boolean(*v, "march.adaptive.enabled")) march.adaptive = *b;
            }
            if (const Json* v = Validator::Find(*adaptive, "kappa")) {
                if (auto d = check.Number(*v, "march.adaptive.kappa", Range{.lo = 0, .hi = 1e6})) march.kappa = *d;
            }
            if (const Json* v = Validator::Find(*adaptive, "start")) {
                if (auto d = check.Number(*v, "march.adaptive.start", kSingleNonNegative)) march.adaptiveStart = *d;
            }
        }
        if (const Json* v = find("jitter")) {
            if (auto b = check.Boolean(*v, "march.jitter")) march.jitter = *b;
        }
        if (const Json* v = find("light")) {
            if (auto kind = check.Choice(*v, "march.light", kMarchLightNames)) march.light = *kind;
        }
        if (const Json* v = find("light_steps")) {
            if (auto n = check.Integer(*v, "march.light_steps", 1, 4096)) march.lightSteps = uint32_t(*n);
        }
        if (const Json* powder = check.Section(*section, "march", "powder", kPowderKeys)) {
            if (const Json* v = Validator::Find(*powder, "enabled")) {
                if (auto b = check.Boolean(*v, "march.powder.enabled")) march.powder = *b;
            }
            if (const Json* v = Validator::Find(*powder, "c")) {
                if (auto d = check.Number(*v, "march.powder.c", Range{.lo = 0, .hi = 1000})) march.powderC = *d;
            }
        }
        if (const Json* v = find("epsilon")) {
            if (auto d = check.Number(*v, "march.epsilon", Range{.lo = 0, .hi = 1, .hiOpen = true})) march.epsilon = *d;
        }
        if (const Json* skipping = check.Section(*section, "march", "skipping", kSkippingKeys)) {
            if (const Json* v = Validator::Find(*skipping, "enabled")) {
                if (auto b = check.Boolean(*v, "march.skipping.enabled")) march.skipping = *b;
            }
            if (const Json* v = Validator::Find(*skipping, "brick")) {
                if (auto n = check.Integer(*v, "march.skipping.brick", 1, 1024)) march.brick = uint32_t(*n);
            }
        }
        if (const Json* v = find("exposure")) {
            if (auto d = check.Number(*v, "march.exposure", kSinglePositive)) march.exposure = *d;
        }
        if (const Json* v = find("tone_map")) {
            if (auto b = check.Boolean(*v, "march.tone_map")) march.toneMap = *b;
        }
        if (const Json* reprojection = check.Section(*section, "march", "reprojection", kReprojectionKeys)) {
            if (const Json* v = Validator::Find(*reprojection, "block")) {
                constexpr int64_t kBlocks[] = {kReprojectionBlocks[0], kReprojectionBlocks[1], kReprojectionBlocks[2]};
                if (auto k = check.IntegerChoice(*v, "march.reprojection.block", kBlocks, "1, 2 or 4"))
                    march.reprojectionBlock = uint32_t(*k);
            }
        }
    }
    // The default light source reads T, which only the shade stage writes.
    if (stages.Has(Stage::RenderMarch) && march.light == MarchLightSource::Shade && !stages.Has(Stage::Shade))
        check.Fail("march.light",
                   "\"shade\" needs stage \"shade\" (add it to stages, or set march.light to \"march\")");
}

}  // namespace cb::scene_io

namespace cb {
namespace {

// SPEC 10: 1e-4 per linear channel on 99.9 % of pixels.
CompareRule MarchImageRule(const Scene&) {
    return {CompareRule::Kind::Image, 1e-4, 0.001, std::numeric_limits<double>::infinity()};
}

// The ray marcher interpolates q between the last two steps, like the splat renderer.
std::vector<Resource> MarchPrevious(const Scene&) { return {Resource::Q}; }

}  // namespace

MarchParams MakeMarchParams(const Scene& sc, const CameraSettings& camera, uint32_t step, uint32_t frame,
                            uint32_t frames) {
    MarchParams p;
    p.camera = MakeCameraFrame(camera, sc.render.width, sc.render.height);
    const float h = float(sc.grid.voxelSize);
    p.origin = {float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    MarchSetup& s = p.setup;
    s.size = {float(sc.grid.size.nx), float(sc.grid.size.ny), float(sc.grid.size.nz)};
    s.tiling = sc.grid.tiling;
    s.invSize = {1.0f / s.size[0], 1.0f / s.size[1], 1.0f / s.size[2]};  // the wrap's factor on every backend
    s.voxelSize = h;
    s.step = float(sc.march.step);
    s.adaptive = sc.march.adaptive;
    s.kappa = float(sc.march.kappa);
    s.adaptiveStart = float(sc.march.adaptiveStart);
    s.sigmaH = MarchOpticalDepthPerVoxel(float(sc.shade.sigma), h);
    s.epsilon = float(sc.march.epsilon);
    s.sun = sc.sun.DirectionAt(step);
    s.background = sc.lighting.Background();
    s.powder = sc.march.powder;
    s.powderC = float(sc.march.powderC);
    s.light = MakeLightTerms(sc, step);
    p.alpha = sc.render.FrameAlpha(frame, frames);
    p.light = sc.march.light;
    p.lightSteps = sc.march.lightSteps;
    p.jitter = sc.march.jitter;
    p.seed = sc.ca.seed;
    p.frame = step;
    p.skipping = sc.march.skipping;
    p.brick = sc.march.brick;
    p.ground = MakeGroundParams(sc);
    return p;
}

namespace {

constexpr auto kMarchCounterFields = FrameCounterFields(kMarchCounters);

FrameToneMap MarchToneMap(const Scene& scene) { return {scene.march.toneMap, float(scene.march.exposure)}; }

// One image for the accuracy measurement; T only with the light source "shade".
Result<AccuracyRender> MarchAccuracyRender(Backend& backend, const Scene& scene, const AccuracyRenderInputs& in) {
    const Buffer* T = nullptr;
    if (scene.march.light == MarchLightSource::Shade) {
        auto shaded = in.shadedT();
        if (!shaded) return std::unexpected(shaded.error());
        T = *shaded;
    }
    auto p = std::make_shared<const MarchParams>(MakeMarchParams(scene, *in.camera, in.step));
    MarchInputs inputs{in.q, in.q, T};
    if (scene.lighting.sky.on) {
        auto skyT = in.shadedSkyT();
        if (!skyT) return std::unexpected(skyT.error());
        inputs.TSky = *skyT;
    }
    return AccuracyRender{[&backend, p, inputs, image = in.image] {
        return backend.RenderMarch(*p, inputs, *image, nullptr);
    }};
}

// The step halved and doubled and quadrupled, adaptive steps, the other light source and its step counts, shade at
// half resolution, jitter, skipping and epsilon toggled, and every phase function against the Mie reference.
std::vector<std::vector<SceneOverride>> MarchAccuracyVariants(const Scene& sc) {
    auto number = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, "%.9g", v);
        return std::string(text);
    };
    std::vector<std::vector<SceneOverride>> out;
    for (double f : {0.5, 2.0, 4.0}) out.push_back({{"march.step", number(sc.march.step * f)}});
    if (!sc.march.adaptive) out.push_back({{"march.adaptive.enabled", "true"}});
    if (sc.march.light == MarchLightSource::Shade) {
        for (int n : {2, 4, 8, 16}) out.push_back({{"march.light", "march"}, {"march.light_steps", std::to_string(n)}});
        if (sc.shade.resolution != 2) out.push_back({{std::string(ShadeResolutionSetting().path), "2"}});
    } else {
        for (uint32_t n : {2u, 4u, 8u, 16u})
            if (n != sc.march.lightSteps) out.push_back({{"march.light_steps", std::to_string(n)}});
        if (sc.stages.Has(Stage::Shade)) out.push_back({{"march.light", "shade"}});
    }
    out.push_back({{"march.jitter", sc.march.jitter ? "false" : "true"}});
    out.push_back({{"march.skipping.enabled", sc.march.skipping ? "false" : "true"}});
    if (sc.march.epsilon != 0) out.push_back({{"march.epsilon", "0"}});
    // Every phase function against the Mie reference, the scene's own included
    // (its row is the cost of approximating Mie); for a Mie scene that row is the scene's.
    for (const auto& [name, kind] : kPhaseKindNames)
        if (kind != PhaseKind::Mie || sc.phase.kind != PhaseKind::Mie)
            out.push_back({{"phase.function", std::string(name)}});
    return out;
}

constexpr std::string_view kMarchImageFields[] = {"march", "render"};
// The reference integrates the light exactly (SPEC 11): the march's steps, its light source and its tone map are
// what it measures, not what it reads.
constexpr std::string_view kMarchReferenceIgnores[] = {"march.step",
                                                       "march.adaptive.enabled",
                                                       "march.adaptive.kappa",
                                                       "march.adaptive.start",
                                                       "march.jitter",
                                                       "march.light",
                                                       "march.light_steps",
                                                       "march.epsilon",
                                                       "march.skipping.enabled",
                                                       "march.skipping.brick",
                                                       "march.exposure",
                                                       "march.tone_map",
                                                       "march.reprojection.block",
                                                       "lighting.eye_scattering"};

// The exact reference's parameters: the march's, with single scattering exact through the scene's phase function.
// Eye scattering, the renderers' stand-in for that, is left out (its error against the reference is the measure).
MarchParams MarchReferenceParams(const Scene& scene, const CameraSettings& camera, uint32_t step) {
    MarchParams p = MakeMarchParams(scene, camera, step);
    p.setup.light.eyeOn = false;
    p.setup.light.phase = scene.phase;
    return p;
}

const RendererDescriptor kMarchRenderer{
    .fileStem = "march",
    .rowLabel = "march",
    .resultsKey = "march_frames",
    .recordKey = "march",
    .counters = kMarchCounterFields,
    .toneMap = MarchToneMap,
    .honoursTiling = true,
    .imageFields = kMarchImageFields,
    .referenceIgnores = kMarchReferenceIgnores,
    .accuracyRender = MarchAccuracyRender,
    .referenceParams = MarchReferenceParams,
    .accuracyVariants = MarchAccuracyVariants,
    .accuracyVariantsHelp =
        "step (x0.5, x2, x4), adaptive step, light source and n_l, jitter, skipping, epsilon 0 "
        "and phase function",
};

}  // namespace

// What its parameters read from the scene (StageDescriptor::sceneFields).
// Besides the light terms' sections, which every renderer reads (core/pipeline/LightTerms.h kLightTermFields).
constexpr std::string_view kRenderMarchSceneFields[] = {
    "march",        "sun",          "shade.sigma",   "ca.seed",        "grid.voxel_size", "grid.origin",
    "grid.tiling",  "render.width", "render.height", "render.cameras", "render.alpha",    "render.frames_per_step",
    "render.ground"};

constexpr std::string_view kRenderMarchSceneKeys[] = {"march"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeRenderMarch() {
    static const StageDescriptor descriptor{
        .stage = Stage::RenderMarch,
        .section = "render",
        .sceneKeys = kRenderMarchSceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadMarch(root, check, scene.stages, scene.march); },
        .reads = {Resource::Q},
        // march.light "shade" (the default) needs T, render.ground G, the sky light T_sky: checked when the scene is
        // loaded.
        .optionalReads = {Resource::T, Resource::Shadow, Resource::TSky, Resource::ColumnSum},
        .readsPrevious = MarchPrevious,
        .writes = {Resource::MarchImage},
        .outputStepsOnly = true,
        .renderer = &kMarchRenderer,
        .symbol = "image",
        .rule = MarchImageRule,
        .sceneFields = kRenderMarchSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallRenderMarch(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record) {
    return RenderEachCamera(
        Stage::RenderMarch, backend, sc, host, io, Resource::MarchImage, record,
        [&](size_t n, FrameRecord& frame, auto timed) {
            const CameraSettings& camera = sc.render.cameras[n];
            MarchParams p = MakeMarchParams(sc, camera.At(host.sequence), host.step, host.frame, host.frames);
            // The previous frame's camera: that of the frame before (the first frame traces every pixel).
            const uint32_t previous = host.sequence > 0 ? host.sequence - 1 : 0;
            p.reprojection = MakeReprojection(sc.march.reprojectionBlock, host.sequence, camera.CutAt(host.sequence),
                                              MakeCameraFrame(camera.At(previous), sc.render.width, sc.render.height));
            // T only where shade runs (the light source "shade").
            MarchInputs in{PreviousOrCurrent(io, Resource::Q), io.Current(Resource::Q), io.Current(Resource::T)};
            in.G = p.ground.on ? io.Current(Resource::Shadow) : nullptr;  // the ground only
            in.TSky = io.Current(Resource::TSky);
            MarchStats stats;
            Status drawn =
                timed([&] { return backend.RenderMarch(p, in, *io.Current(Resource::MarchImage, n), &stats); });
            frame.counters = ToFrameCounters(stats, kMarchCounters);
            return drawn;
        });
}

}  // namespace cb
