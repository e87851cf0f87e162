#include "core/stages/shadow/Shadow.h"

#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"

namespace cb {
namespace {

constexpr ChoiceSetting kShadowForm{"shadow.form", TableNames<kShadowFormNames>,
                                    [](const Scene& s) { return std::string(ShadowFormName(s.shadow.form)); }};
constexpr ChoiceSetting kShadowChoices[] = {kShadowForm};

}  // namespace
}  // namespace cb

namespace cb::scene_io {
namespace {

constexpr std::string_view kShadowKeys[] = {"form", "kappa", "coverage", "density_factor"};

}  // namespace

void ReadShadow(const Json& root, Validator& check, ShadowSettings& shadow) {
    const Json* section = check.Section(root, "", "shadow", kShadowKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "form")) {
        if (auto kind = check.Choice(*v, kShadowForm.path, kShadowFormNames)) shadow.form = *kind;
    }
    if (const Json* v = Validator::Find(*section, "kappa")) {
        if (auto d = check.Number(*v, "shadow.kappa", kSingleNonNegative)) shadow.kappa = *d;
    }
    if (const Json* v = Validator::Find(*section, "coverage")) {
        if (auto d = check.Number(*v, "shadow.coverage", kProbability)) shadow.coverage = *d;
    }
    if (const Json* v = Validator::Find(*section, "density_factor")) {
        if (auto d = check.Number(*v, "shadow.density_factor", kProbability)) shadow.densityFactor = *d;
    }
}

}  // namespace cb::scene_io

namespace cb {
namespace {

CompareRule ShadowRule(const Scene&) { return {CompareRule::Kind::Absolute, 1e-5}; }

}  // namespace

ShadowParams MakeShadowParams(const Scene& sc, uint32_t step) {
    ShadowParams p;
    p.sun = sc.sun.DirectionAt(step);
    p.form = sc.shadow.form;
    p.sigma = float(sc.shade.sigma);
    p.voxelSize = float(sc.grid.voxelSize);
    p.kappa = float(sc.shadow.kappa);
    p.coverage = float(sc.shadow.coverage);
    p.densityFactor = float(sc.shadow.densityFactor);
    p.nz = sc.grid.size.nz;
    return p;
}

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kShadowSceneFields[] = {"shadow", "shade.sigma", "sun", "grid.voxel_size"};

constexpr std::string_view kShadowSceneKeys[] = {"shadow"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeShadow() {
    static const StageDescriptor descriptor{
        .stage = Stage::Shadow,
        .section = "shadow",
        .sceneKeys = kShadowSceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadShadow(root, check, scene.shadow); },
        .reads = {Resource::ColumnSum},
        .writes = {Resource::Shadow},
        .outputStepsOnly = true,
        .skipsUnchangedInputs = true,
        .sunAt = [](const Scene& sc, uint32_t step) { return sc.sun.DirectionAt(step); },
        .symbol = "G",
        .rule = ShadowRule,
        .choices = kShadowChoices,
        .sceneFields = kShadowSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallShadow(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record) {
    const ShadowParams p = MakeShadowParams(sc, host.step);
    return TimedStage(Stage::Shadow, backend, host, record, [&] {
        return backend.Shadow(p, *io.Current(Resource::ColumnSum), *io.Current(Resource::Shadow));
    });
}

}  // namespace cb
