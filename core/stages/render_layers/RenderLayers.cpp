#include "core/stages/render_layers/RenderLayers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <string_view>

#include "core/math/Noise.h"
#include "core/pipeline/LightTerms.h"
#include "core/scene/SceneReaders.h"
#include "core/stages/noise/Noise.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kLayersKeys[] = {"count",   "extent",  "fade",        "max_length", "wind",
                                            "wang",    "relight", "lod0_radius", "exposure",   "billboard_spacing",
                                            "tone_map"};
constexpr std::array<NamedValue<LayersRelight>, 2> kLayersRelightNames{{
    {"shade", LayersRelight::Shade},
    {"vector", LayersRelight::Vector},
}};

// At most this many layers per voxel edge of height: SPEC 15 measures up to 4; more only multiplies the work.
constexpr uint32_t kMaxLayersPerVoxel = 16;

}  // namespace

void ReadLayers(const Json& root, Validator& check, std::optional<uint32_t> nz, LayersSettings& layers) {
    const Json* section = check.Section(root, "", "layers", kLayersKeys);
    if (!section) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    if (const Json* v = find("count")) {
        // 16 layers per voxel of height (the grid's nz).
        const int64_t most = nz ? int64_t(kMaxLayersPerVoxel) * *nz : int64_t(kU32Max);
        if (auto n = check.Integer(*v, "layers.count", 1, most)) layers.count = uint32_t(*n);
    }
    if (const Json* v = find("extent")) {
        if (auto d = check.Number(*v, "layers.extent", kSinglePositive)) layers.extent = *d;
    }
    if (const Json* v = find("fade")) {
        if (auto d = check.Number(*v, "layers.fade", Range{.lo = 0, .hi = 1})) layers.fade = *d;
    }
    if (const Json* v = find("max_length")) {
        if (auto d = check.Number(*v, "layers.max_length", kSinglePositive)) layers.maxLength = *d;
    }
    if (const Json* v = find("wind")) {
        if (auto a = check.Numbers<2>(*v, "layers.wind", Range{.lo = -1e6, .hi = 1e6})) layers.wind = *a;
    }
    ReadCoverage(*section, "layers", "wang", check, layers.wang);
    if (const Json* v = find("relight")) {
        if (auto kind = check.Choice(*v, "layers.relight", kLayersRelightNames)) layers.relight = *kind;
    }
    if (const Json* v = find("lod0_radius")) {
        if (auto d = check.Number(*v, "layers.lod0_radius", kSingleNonNegative)) layers.lod0Radius = *d;
    }
    if (const Json* v = find("billboard_spacing")) {
        if (auto d = check.Number(*v, "layers.billboard_spacing", kSinglePositive)) layers.billboardSpacing = *d;
    }
    if (const Json* v = find("exposure")) {
        if (auto d = check.Number(*v, "layers.exposure", kSinglePositive)) layers.exposure = *d;
    }
    if (const Json* v = find("tone_map")) {
        if (auto b = check.Boolean(*v, "layers.tone_map")) layers.toneMap = *b;
    }
}

void CheckLayersLod0(const Scene& sc, const Extent3* grid, Validator& check) {
    const double r0 = sc.layers.lod0Radius;
    if (!(r0 > 0)) return;
    // LOD0 lies inside the layers' extent: beyond it the annulus would be empty and the billboards reach past it.
    if (sc.layers.extent > 0) {
        if (r0 > sc.layers.extent)
            check.Fail("layers.lod0_radius", "must not exceed layers.extent (" + FormatNumber(sc.layers.extent) +
                                                 "), got " + FormatNumber(r0));
    } else {
        for (const CameraSettings& camera : sc.render.cameras)
            if (r0 > camera.farPlane) {
                check.Fail("layers.lod0_radius", "must not exceed the layers' extent, camera \"" + camera.name +
                                                     "\"'s far plane (" + FormatNumber(camera.farPlane) + "), got " +
                                                     FormatNumber(r0));
                break;
            }
    }
    if (!grid) return;
    const double bound = LayersBillboardBound(sc.layers, sc.grid.voxelSize, sc.grid.size.nz);
    if (bound > kMaxLayersBillboards)
        check.Fail("layers.lod0_radius", "LOD0 would hold up to " + FormatNumber(std::floor(bound)) +
                                             " billboards ((2 r0 / p_s + 2)^2 on each layer), more than " +
                                             FormatNumber(kMaxLayersBillboards) +
                                             "; lower it or raise layers.billboard_spacing, got " + FormatNumber(r0));
}

}  // namespace cb::scene_io

namespace cb {
namespace {

// Like the other renderers, the layers interpolate q between the last two steps.
std::vector<Resource> LayersPrevious(const Scene&) { return {Resource::Q}; }

}  // namespace

LayersParams MakeLayersParams(const Scene& sc, const CameraSettings& camera, uint32_t step, uint32_t frame,
                              uint32_t frames) {
    LayersParams p;
    p.camera = MakeCameraFrame(camera, sc.render.width, sc.render.height);
    const float h = float(sc.grid.voxelSize);
    p.origin = {float(sc.grid.origin[0]), float(sc.grid.origin[1]), float(sc.grid.origin[2])};
    p.alpha = sc.render.FrameAlpha(frame, frames);
    LayersSetup& s = p.setup;
    const Extent3 e = sc.grid.size;
    for (int a = 0; a < 3; ++a) s.eye[a] = (p.camera.eye[a] - p.origin[a]) / h;
    s.size = {float(e.nx), float(e.ny), float(e.nz)};
    s.invSize = {1.0f / s.size[0], 1.0f / s.size[1], 1.0f / s.size[2]};
    s.voxelSize = h;
    s.count = sc.layers.count > 0 ? sc.layers.count : e.nz;
    s.spacing = float(double(e.nz) / double(s.count));
    const double extent = (sc.layers.extent > 0 ? sc.layers.extent : camera.farPlane) / sc.grid.voxelSize;
    s.outer2 = float(std::min(extent * extent, 1e36));
    // extent^2 - ((1 - fade) extent)^2 = extent^2 fade (2 - fade).
    const double band = extent * extent * sc.layers.fade * (2.0 - sc.layers.fade);
    s.fadeInv2 = band > 0 && extent * extent <= 1e36 ? float(1.0 / band) : 0.0f;
    s.maxLength = float(sc.layers.maxLength > 0 ? sc.layers.maxLength : double(e.nz));
    s.sigmaH = MarchOpticalDepthPerVoxel(float(sc.shade.sigma), h);
    s.tiling = sc.grid.tiling;
    // The drift at the frame's time, in double on the host; with tiling reduced modulo the period, so the
    // per-fragment float stays within a tile of the eye whatever the step.
    const double time = double(step) - 1.0 + double(p.alpha);
    for (int a = 0; a < 2; ++a) {
        double d = time * sc.layers.wind[a] / sc.grid.voxelSize;
        const double n = a == 0 ? e.nx : e.ny;
        if (s.tiling) d -= n * std::floor(d / n);
        s.drift[a] = float(d);
    }
    s.sun = sc.sun.DirectionAt(step);
    // Relighting: shade's T is the first step's (ShadeSunAt); n . s = T (s0 . s) with n = T s0.
    if (sc.layers.relight == LayersRelight::Vector)
        s.lightScale = std::max(0.0f, MarchDot(sc.sun.DirectionAt(0), s.sun));
    s.background = sc.lighting.Background();
    s.light = MakeLightTerms(sc, step);
    s.light.pointOn = false;  // no transmittance toward the point light in the layers: it stays off
    s.wang = sc.layers.wang.enabled;
    SetLayersLod0(s, sc.layers.lod0Radius / sc.grid.voxelSize, LayersBillboardSpacing(sc) / sc.grid.voxelSize);
    s.coverage = float(sc.layers.wang.coverage);
    s.density = float(sc.layers.wang.density);
    return p;
}

double LayersBillboardSpacing(const Scene& sc) {
    return sc.layers.billboardSpacing > 0 ? sc.layers.billboardSpacing : sc.grid.voxelSize;
}

std::vector<float> MakeLayersMap(const Scene& sc, uint32_t step) {
    if (!sc.layers.wang.enabled) return {};
    NoiseSettings settings = sc.noise;  // its seed and drift; the map alone is evaluated
    settings.coverage = sc.layers.wang;
    settings.detail.enabled = false;
    settings.towers.clear();
    const Extent3 e = sc.grid.size;
    const noise::NoiseForm form(settings, e);
    const noise::StepOffsets offsets = form.Offsets(step);
    std::vector<float> map(size_t(e.nx) * e.ny);
    for (uint32_t j = 0; j < e.ny; ++j)
        for (uint32_t i = 0; i < e.nx; ++i) map[i + size_t(e.nx) * j] = form.Map(offsets, i, j);
    return map;
}

namespace {

constexpr auto kLayersCounterFields = FrameCounterFields(kLayersCounters);

FrameToneMap LayersToneMap(const Scene& scene) { return {scene.layers.toneMap, float(scene.layers.exposure)}; }
bool LayersRelights(const Scene& scene) { return scene.layers.relight == LayersRelight::Vector; }
constexpr std::string_view kLayersRelightFields[] = {"layers.relight"};

// One image for the accuracy measurement; the wang map is made before the timed calls, as in a run.
Result<AccuracyRender> LayersAccuracyRender(Backend& backend, const Scene& scene, const AccuracyRenderInputs& in) {
    auto T = in.shadedT();
    if (!T) return std::unexpected(T.error());
    auto map = std::make_shared<const std::vector<float>>(MakeLayersMap(scene, in.step));
    auto p = std::make_shared<LayersParams>(MakeLayersParams(scene, *in.camera, in.step));
    p->setup.map = map->empty() ? nullptr : map->data();
    LayersInputs inputs{in.q, in.q, *T};
    if (scene.lighting.sky.on) {
        auto skyT = in.shadedSkyT();
        if (!skyT) return std::unexpected(skyT.error());
        inputs.TSky = *skyT;
    }
    return AccuracyRender{[&backend, p, map, inputs, image = in.image] {
        return backend.RenderLayers(*p, inputs, *image, nullptr);
    }};
}

// SPEC 15's layers per voxel of height, 1/2, 1, 2 and 4 (the scene's count left out), and grazing views.
std::vector<std::vector<SceneOverride>> LayersAccuracyVariants(const Scene& sc) {
    auto number = [](const char* format, double v) {
        char text[48];
        std::snprintf(text, sizeof text, format, v);
        return std::string(text);
    };
    std::vector<std::vector<SceneOverride>> out;
    const uint32_t nz = sc.grid.size.nz, count = sc.layers.count > 0 ? sc.layers.count : nz;
    for (uint32_t n : {nz / 2, nz, 2 * nz, 4 * nz})
        if (n >= 1 && n != count) out.push_back({{"layers.count", std::to_string(n)}});
    // Grazing views, where the paper's layers show gaps: one camera at the slab's mid-height, a quarter of the grid
    // outside it in x, looking along +x raised by 1, 5 and 20 degrees.
    const double h = sc.grid.voxelSize, nx = sc.grid.size.nx;
    const std::array<double, 3> eye = {sc.grid.origin[0] - 0.25 * nx * h, sc.grid.origin[1] + 0.5 * sc.grid.size.ny * h,
                                       sc.grid.origin[2] + 0.5 * nz * h};
    for (double degrees : {1.0, 5.0, 20.0}) {
        const double e = degrees * std::numbers::pi / 180, reach = nx * h;
        const std::array<double, 3> target = {eye[0] + reach * std::cos(e), eye[1], eye[2] + reach * std::sin(e)};
        out.push_back({{"render.cameras", "[{\"name\": \"elevation-" + number("%.0f", degrees) + "\", \"eye\": [" +
                                              number("%.6g", eye[0]) + ", " + number("%.6g", eye[1]) + ", " +
                                              number("%.6g", eye[2]) + "], \"target\": [" + number("%.6g", target[0]) +
                                              ", " + number("%.6g", target[1]) + ", " + number("%.6g", target[2]) +
                                              "]}]"}});
    }
    return out;
}

constexpr std::string_view kLayersImageFields[] = {"layers", "render"};
constexpr std::string_view kLayersReferenceIgnores[] = {"layers"};

const RendererDescriptor kLayersRenderer{
    .fileStem = "layers",
    .rowLabel = "layers",
    .resultsKey = "layers_frames",
    .recordKey = "layers",
    .counters = kLayersCounterFields,
    .toneMap = LayersToneMap,
    .honoursTiling = true,
    .relights = LayersRelights,
    .relightFields = kLayersRelightFields,
    .imageFields = kLayersImageFields,
    .referenceIgnores = kLayersReferenceIgnores,
    .accuracyRender = LayersAccuracyRender,
    .accuracyVariants = LayersAccuracyVariants,
    .accuracyVariantsHelp =
        "layers.count (nz/2, nz, 2 nz, 4 nz) and three grazing views (one camera at the slab's "
        "mid-height looking up 1, 5 and 20 degrees)",
};

}  // namespace

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kRenderLayersSceneFields[] = {
    "layers",      "noise",        "sun",           "shade.sigma",    "grid.voxel_size", "grid.origin",
    "grid.tiling", "render.width", "render.height", "render.cameras", "render.alpha",    "render.frames_per_step"};

constexpr std::string_view kRenderLayersSceneKeys[] = {"layers"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeRenderLayers() {
    static const StageDescriptor descriptor{
        .stage = Stage::RenderLayers,
        .section = "layers",
        .sceneKeys = kRenderLayersSceneKeys,
        .readSettings =
            [](const scene_io::Json& root, scene_io::Validator& check, const Extent3* grid, Scene& scene) {
                scene_io::ReadLayers(root, check, grid ? std::optional(grid->nz) : std::nullopt, scene.layers);
                scene_io::CheckLayersLod0(scene, grid, check);
            },
        .reads = {Resource::Q, Resource::T},
        // The sky light's T_sky, the shafts' D: checked when the scene is loaded.
        .optionalReads = {Resource::TSky, Resource::ColumnSum},
        .readsPrevious = LayersPrevious,
        .writes = {Resource::LayersImage},
        .outputStepsOnly = true,
        .renderer = &kLayersRenderer,
        .symbol = "image",
        .rule = ImageRuleSpec8,  // SPEC 15 takes SPEC 8's rule
        .sceneFields = kRenderLayersSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallRenderLayers(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                        StageCallRecord& record) {
    // The wang map is host work shared by all backends, outside the stage time: one per call, for every camera.
    const std::vector<float> map = MakeLayersMap(sc, host.step);
    return RenderEachCamera(
        Stage::RenderLayers, backend, sc, host, io, Resource::LayersImage, record,
        [&](size_t n, FrameRecord& frame, auto timed) {
            LayersParams p =
                MakeLayersParams(sc, sc.render.cameras[n].At(host.sequence), host.step, host.frame, host.frames);
            p.setup.map = map.empty() ? nullptr : map.data();
            const LayersInputs in{PreviousOrCurrent(io, Resource::Q), io.Current(Resource::Q), io.Current(Resource::T),
                                  io.Current(Resource::TSky), host.inputsStamp};
            LayersStats stats;
            Status drawn =
                timed([&] { return backend.RenderLayers(p, in, *io.Current(Resource::LayersImage, n), &stats); });
            frame.counters = ToFrameCounters(stats, kLayersCounters);
            return drawn;
        });
}

}  // namespace cb
