#include "core/stages/shade/Shade.h"

#include <numbers>

#include "core/pipeline/ShadePlan.h"
#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"

namespace cb {
namespace {

std::vector<std::string> ShadeResolutionValues() {
    std::vector<std::string> values;
    for (const int64_t f : kShadeResolutions) values.push_back(std::to_string(f));
    return values;
}

// shade's settings with a few values each, in the order conform's matrix and accuracy walk them.
constexpr ChoiceSetting kShadeAttenuation{"shade.attenuation", TableNames<kAttenuationKindNames>, [](const Scene& s) {
                                              return std::string(AttenuationKindName(s.shade.attenuation));
                                          }};
constexpr ChoiceSetting kShadeFilter{"shade.filter", TableNames<kSampleFilterNames>,
                                     [](const Scene& s) { return std::string(SampleFilterName(s.shade.filter)); }};
constexpr ChoiceSetting kShadeResolution{"shade.resolution", ShadeResolutionValues,
                                         [](const Scene& s) { return std::to_string(s.shade.resolution); }};
constexpr ChoiceSetting kShadeStorage{"shade.storage", TableNames<kStorageFormatNames>,
                                      [](const Scene& s) { return std::string(StorageFormatName(s.shade.storage)); }};
constexpr ChoiceSetting kShadeScattering{"shade.scattering.enabled", BooleanValues,
                                         [](const Scene& s) { return BooleanText(s.shade.scattering); }};
constexpr ChoiceSetting kShadeChoices[] = {kShadeAttenuation, kShadeFilter, kShadeResolution, kShadeStorage,
                                           kShadeScattering};

}  // namespace
}  // namespace cb

namespace cb::scene_io {
namespace {

constexpr std::string_view kShadeKeys[] = {"attenuation", "sigma",   "thesis_ar", "filter",
                                           "resolution",  "storage", "scattering"};
constexpr std::string_view kScatteringKeys[] = {"enabled", "albedo", "solid_angle"};

}  // namespace

void ReadShade(const Json& root, Validator& check, ShadeSettings& shade) {
    const Json* section = check.Section(root, "", "shade", kShadeKeys);
    if (!section) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    if (const Json* v = find("attenuation")) {
        if (auto kind = check.Choice(*v, kShadeAttenuation.path, kAttenuationKindNames)) shade.attenuation = *kind;
    }
    if (const Json* v = find("sigma")) {
        if (auto d = check.Number(*v, "shade.sigma", kSingleNonNegative)) shade.sigma = *d;
    }
    if (const Json* v = find("thesis_ar")) {
        if (auto d = check.Number(*v, "shade.thesis_ar", kProbability)) shade.thesisAr = *d;
    }
    if (const Json* v = find("filter")) {
        if (auto filter = check.Choice(*v, kShadeFilter.path, kSampleFilterNames)) shade.filter = *filter;
    }
    if (const Json* v = find("resolution")) {
        if (auto n = check.IntegerChoice(*v, kShadeResolution.path, kShadeResolutions, kShadeResolutionsText))
            shade.resolution = int(*n);
    }
    if (const Json* v = find("storage")) {
        if (auto format = check.Choice(*v, kShadeStorage.path, kStorageFormatNames)) shade.storage = *format;
    }
    const Json* scattering = check.Section(*section, "shade", "scattering", kScatteringKeys);
    if (!scattering) return;
    if (const Json* v = Validator::Find(*scattering, "enabled")) {
        if (auto b = check.Boolean(*v, kShadeScattering.path)) shade.scattering = *b;
    }
    if (const Json* v = Validator::Find(*scattering, "albedo")) {
        if (auto d = check.Number(*v, "shade.scattering.albedo", kProbability)) shade.albedo = *d;
    }
    if (const Json* v = Validator::Find(*scattering, "solid_angle")) {
        const Range solidAngle{.lo = 0, .loOpen = true, .hi = 4 * std::numbers::pi};
        if (auto d = check.Number(*v, "shade.scattering.solid_angle", solidAngle)) shade.solidAngle = *d;
    }
}

}  // namespace cb::scene_io

namespace cb {

// SPEC 6: 1e-5 in fp32; one storage quantum in the narrower formats, compared on the stored codes.
CompareRule ShadeCompareRule(const Scene& scene) {
    const StorageFormat storage = scene.shade.storage;
    if (storage == StorageFormat::Fp32) return {CompareRule::Kind::Absolute, 1e-5};
    CompareRule rule{CompareRule::Kind::Codes, 1};
    rule.storage = storage;
    return rule;
}

namespace {

// Time-slicing's shares (SliceRange): the sweep's slices, whose axis follows the sun at the step.
uint32_t SweepSlices(const Scene& scene, uint32_t step) {
    ShadeParams p;  // the plan's slices depend on the sun and the resolution alone
    p.sun = ShadeSunAt(scene, step);
    p.resolution = scene.shade.resolution;
    return MakeShadePlan(p, scene.grid.size).nw;
}

}  // namespace

const ChoiceSetting& ShadeResolutionSetting() { return kShadeResolution; }
const ChoiceSetting& ShadeScatteringSetting() { return kShadeScattering; }

Vec3 ShadeSunAt(const Scene& sc, uint32_t step) {
    return sc.needs.shadeOnce ? sc.sun.DirectionAt(0) : sc.sun.DirectionAt(step);
}

ShadeParams MakeShadeParams(const Scene& sc, uint32_t step) {
    ShadeParams p;
    p.sun = ShadeSunAt(sc, step);
    p.attenuation = sc.shade.attenuation;
    p.sigma = float(sc.shade.sigma);
    p.voxelSize = float(sc.grid.voxelSize);
    p.thesisAr = float(sc.shade.thesisAr);
    p.filter = sc.shade.filter;
    p.resolution = sc.shade.resolution;
    p.storage = sc.shade.storage;
    p.scattering = sc.shade.scattering;
    p.albedo = float(sc.shade.albedo);
    p.solidAngle = float(sc.shade.solidAngle);
    p.phase = sc.phase;
    return p;
}

// What its parameters read from the scene (StageDescriptor::sceneFields).
// (A renderer that relights fixes the sun it receives, Scene::needs: its RendererDescriptor::relightFields.)
constexpr std::string_view kShadeSceneFields[] = {"shade", "sun", "phase", "grid.voxel_size"};

constexpr std::string_view kShadeSceneKeys[] = {"shade"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeShade() {
    static const StageDescriptor descriptor{
        .stage = Stage::Shade,
        .section = "shade",
        .sceneKeys = kShadeSceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadShade(root, check, scene.shade); },
        .reads = {Resource::Q},
        .writes = {Resource::T},
        .outputStepsOnly = true,
        .skipsUnchangedInputs = true,
        .sunAt = ShadeSunAt,
        .shareCount = SweepSlices,
        .symbol = "T",
        .rule = ShadeCompareRule,
        .ruleNote = "one storage quantum with fp16 or unorm8 storage",
        .choices = kShadeChoices,
        .sceneFields = kShadeSceneFields,
        .readsRendererNeeds = true,  // shadeOnce
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallShade(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                 StageCallRecord& record) {
    ShadeParams p = MakeShadeParams(sc, host.step);
    p.slices = host.slices;
    return TimedStage(Stage::Shade, backend, host, record,
                      [&] { return backend.Shade(p, *io.Current(Resource::Q), *io.Current(Resource::T)); });
}

}  // namespace cb
