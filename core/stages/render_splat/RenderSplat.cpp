#include "core/stages/render_splat/RenderSplat.h"

#include <algorithm>
#include <chrono>
#include <memory>

#include "core/pipeline/LightTerms.h"
#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"
#include "core/stages/density/Density.h"

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
    p.background = sc.lighting.Background();
    p.light = MakeLightTerms(sc, step);
    p.light.pointOn = false;  // no transmittance toward the point light in the splats: it stays off
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

namespace {

constexpr auto kSplatCounterFields = FrameCounterFields(kSplatCounters);

// One image for the accuracy measurement; the density stage's occupancy (read when skipping) first, untimed.
Result<AccuracyRender> SplatAccuracyRender(Backend& backend, const Scene& scene, const AccuracyRenderInputs& in) {
    auto T = in.shadedT();
    if (!T) return std::unexpected(T.error());
    auto p = std::make_shared<SplatParams>(MakeSplatParams(scene, *in.camera));
    auto order = std::make_shared<const SplatOrder>(
        MakeSplatOrder(p->camera, scene.grid.size, scene.grid.origin, scene.grid.voxelSize));
    p->order = order.get();
    const DensityParams dp = MakeDensityParams(scene);
    const Extent3 e = scene.grid.size;
    auto D = backend.CreateBuffer(BufferFormat::F32, {e.nx, e.ny, 1});
    auto tiles = backend.CreateBuffer(BufferFormat::U8, {CeilDiv(e.nx, dp.tile), CeilDiv(e.ny, dp.tile), 1});
    auto bands =
        backend.CreateBuffer(BufferFormat::U8, {CeilDiv(e.nx, dp.tile), CeilDiv(e.ny, dp.tile), CeilDiv(e.nz, dp.band)});
    if (!D || !tiles || !bands) return MakeError("cannot create the density buffers");
    AccuracyRender out;
    if (backend.Supports(Stage::Density)) {
        DensityOutputs outs{D->get(), tiles->get(), bands->get(), 0};
        const auto start = std::chrono::steady_clock::now();
        if (Status s = backend.Density(dp, *in.q, nullptr, outs); !s) return MakeError("density: " + s.error().message);
        out.prepMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    } else {
        p->skipping = false;
    }
    std::shared_ptr<Buffer> occupancy[] = {std::move(*D), std::move(*tiles), std::move(*bands)};
    SplatInputs inputs{in.q, in.q, *T, occupancy[1].get(), occupancy[1].get(), occupancy[2].get(), occupancy[2].get()};
    if (scene.lighting.sky.on) {
        auto skyT = in.shadedSkyT();
        if (!skyT) return std::unexpected(skyT.error());
        inputs.TSky = *skyT;
    }
    out.call = [&backend, p, order, occupancy, inputs, image = in.image] {
        return backend.RenderSplat(*p, inputs, *image, nullptr);
    };
    return out;
}

constexpr std::string_view kSplatImageFields[] = {"render"};
constexpr std::string_view kSplatReferenceIgnores[] = {"render.q_min", "render.splat_scale", "render.opacity",
                                                       "render.culling", "render.skipping"};

nlohmann::json SplatConformOptions(const Scene& scene) {
    return {{"phase", PhaseKindName(scene.phase.kind)},
            {"culling", scene.splat.culling},
            {"skipping", scene.splat.skipping},
            {"storage", StorageFormatName(scene.shade.storage)},
            {"cameras", scene.render.cameras.size()},
            {"frames_per_step", std::max(scene.render.framesPerStep, 1u)}};
}

const RendererDescriptor kSplatRenderer{
    .fileStem = "splat",
    .rowLabel = "frame",
    .resultsKey = "frames",
    .recordKey = "",
    .counters = kSplatCounterFields,
    .imageFields = kSplatImageFields,
    .referenceIgnores = kSplatReferenceIgnores,
    .accuracyRender = SplatAccuracyRender,
    .conformOptions = SplatConformOptions,
    .conformVariesPhase = true,
};

}  // namespace

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kRenderSplatSceneFields[] = {"render",      "sun",          "grid.voxel_size",
                                                        "grid.origin", "density.tile", "density.band"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeRenderSplat() {
    static const StageDescriptor descriptor{
        .stage = Stage::RenderSplat,
        .section = "render",
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadSplat(root, check, scene.splat); },
        .reads = {Resource::Q, Resource::T, Resource::Tiles, Resource::Bands},
        // render.ground needs G, the sky light T_sky, the shafts D: each checked when the scene is loaded.
        .optionalReads = {Resource::Shadow, Resource::TSky, Resource::ColumnSum},
        .readsPrevious = SplatPrevious,
        .writes = {Resource::SplatImage},
        .outputStepsOnly = true,
        .renderer = &kSplatRenderer,
        .symbol = "image",
        .rule = ImageRuleSpec8,
        .choices = kSplatChoices,
        .sceneFields = kRenderSplatSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallRenderSplat(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record) {
    return RenderEachCamera(
        Stage::RenderSplat, backend, sc, host, io, Resource::SplatImage, record,
        [&](size_t n, FrameRecord& frame, auto timed) {
            SplatParams p =
                MakeSplatParams(sc, sc.render.cameras[n].At(host.sequence), host.step, host.frame, host.frames);
            // The order is host work shared by all backends, outside the stage time.
            const SplatOrder order = MakeSplatOrder(p.camera, sc.grid.size, sc.grid.origin, sc.grid.voxelSize);
            p.order = &order;
            SplatInputs in{
                PreviousOrCurrent(io, Resource::Q), io.Current(Resource::Q),     io.Current(Resource::T),
                io.Previous(Resource::Tiles),       io.Current(Resource::Tiles), io.Previous(Resource::Bands),
                io.Current(Resource::Bands)};
            in.G = p.ground.on ? io.Current(Resource::Shadow) : nullptr;  // the ground only
            in.TSky = io.Current(Resource::TSky);
            SplatStats stats;
            Status drawn =
                timed([&] { return backend.RenderSplat(p, in, *io.Current(Resource::SplatImage, n), &stats); });
            frame.counters = ToFrameCounters(stats, kSplatCounters);
            return drawn;
        });
}

}  // namespace cb
