#include "core/stages/render_splat/RenderSplat.h"

#include "core/scene/SceneReaders.h"

namespace cb {
namespace {

constexpr ChoiceSetting kSplatCulling{"render.culling", BooleanValues,
                                      [](const Scene& s) { return BooleanText(s.splat.culling); }};
constexpr ChoiceSetting kSplatSkipping{"render.skipping", BooleanValues,
                                       [](const Scene& s) { return BooleanText(s.splat.skipping); }};
constexpr ChoiceSetting kSplatChoices[] = {kSplatCulling, kSplatSkipping};

}  // namespace
}  // namespace cb

namespace cb::scene_io {

// The splat renderer's fields of the `render` section (its keys are checked by ReadRender).
void ReadSplat(const Json& root, Validator& check, SplatSettings& splat) {
    const Json* section = Validator::Find(root, "render");
    if (!section || !section->is_object()) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    auto field = [](std::string_view key) { return JoinField("render", key); };
    if (const Json* v = find("q_min")) {
        if (auto d = check.Number(*v, field("q_min"), kNonNegative)) splat.qMin = *d;
    }
    if (const Json* v = find("splat_scale")) {
        if (auto d = check.Number(*v, field("splat_scale"), kPositive)) splat.splatScale = *d;
    }
    if (const Json* v = find("opacity")) {
        if (auto d = check.Number(*v, field("opacity"), kProbability)) splat.opacity = *d;
    }
    if (const Json* v = find("culling")) {
        if (auto b = check.Boolean(*v, kSplatCulling.path)) splat.culling = *b;
    }
    if (const Json* v = find("skipping")) {
        if (auto b = check.Boolean(*v, kSplatSkipping.path)) splat.skipping = *b;
    }
}

}  // namespace cb::scene_io

namespace cb {
namespace {

// SPEC 8: per channel 2/255 on 99.9 % of pixels, 8/255 everywhere.
CompareRule SplatImageRule(const Scene&) { return {CompareRule::Kind::Image, 2.0 / 255.0, 0.001, 8.0 / 255.0}; }

// The splat renderer interpolates q between the last two steps, and skips
// boxes empty in both steps' occupancy.
std::vector<Resource> SplatPrevious(const Scene& scene) {
    if (scene.splat.skipping) return {Resource::Q, Resource::Tiles, Resource::Bands};
    return {Resource::Q};
}

}  // namespace

SplatParams MakeSplatParams(const Scene& sc, const CameraSettings& camera, uint32_t step, uint32_t frame,
                            uint32_t frames) {
    SplatParams p;
    p.camera = MakeCameraFrame(camera, sc.render.width, sc.render.height);
    p.sun = sc.sun.DirectionAt(step);
    p.sunRadiance = sc.sun.Radiance();
    p.ambient = sc.lighting.Ambient();
    p.background = sc.lighting.Background();
    p.phase = sc.phase;
    p.qMin = float(sc.splat.qMin);
    p.splatDiameter = float(sc.splat.splatScale * sc.grid.voxelSize);
    p.opacity = float(sc.splat.opacity);
    p.alpha = sc.render.FrameAlpha(frame, frames);
    p.origin = {float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    p.voxelSize = float(sc.grid.voxelSize);
    p.culling = sc.splat.culling;
    p.skipping = sc.splat.skipping;
    p.tile = sc.density.tile;
    p.band = sc.density.band;
    p.ground = MakeGroundParams(sc);
    return p;
}

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kRenderSplatSceneFields[] = {
    "render", "sun", "lighting", "phase", "grid.voxel_size", "grid.origin", "density.tile", "density.band"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeRenderSplat() {
    static const StageDescriptor descriptor{
        .stage = Stage::RenderSplat,
        .section = "render",
        .reads = {Resource::Q, Resource::T, Resource::Tiles, Resource::Bands},
        .optionalReads = {Resource::Shadow},  // render.ground needs it: checked when the scene is loaded
        .readsPrevious = SplatPrevious,
        .writes = {Resource::SplatImage},
        .outputStepsOnly = true,
        .renderer = true,
        .symbol = "image",
        .rule = SplatImageRule,
        .choices = kSplatChoices,
        .sceneFields = kRenderSplatSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallRenderSplat(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record) {
    return RenderEachCamera(
        Stage::RenderSplat, backend, sc, host, record, [&](size_t n, FrameRecord& frame, auto timed) {
            SplatParams p = MakeSplatParams(sc, sc.render.cameras[n], host.step, host.frame, host.frames);
            // The order is host work shared by all backends, outside the stage time.
            const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
            p.order = &order;
            SplatInputs in{
                PreviousOrCurrent(io, Resource::Q), io.Current(Resource::Q),     io.Current(Resource::T),
                io.Previous(Resource::Tiles),       io.Current(Resource::Tiles), io.Previous(Resource::Bands),
                io.Current(Resource::Bands)};
            in.G = p.ground.on ? io.Current(Resource::Shadow) : nullptr;  // the ground only
            return timed(
                [&] { return backend.RenderSplat(p, in, *io.Current(Resource::SplatImage, n), &frame.stats); });
        });
}

}  // namespace cb
