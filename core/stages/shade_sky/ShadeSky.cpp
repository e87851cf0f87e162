#include "core/stages/shade_sky/ShadeSky.h"

#include "core/stages/shade/Shade.h"

namespace cb {

ShadeParams MakeShadeSkyParams(const Scene& scene) {
    ShadeParams p = MakeShadeParams(scene, 0);
    p.sun = scene.lighting.sky.Direction();
    return p;
}

namespace {

Vec3 SkyDirectionAt(const Scene& scene, uint32_t) { return scene.lighting.sky.Direction(); }

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kShadeSkySceneFields[] = {"shade", "lighting.sky", "phase", "grid.voxel_size"};

}  // namespace

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeShadeSky() {
    static const StageDescriptor descriptor{
        .stage = Stage::ShadeSky,
        .section = "",
        .reads = {Resource::Q},
        .writes = {Resource::TSky},
        .outputStepsOnly = true,
        .skipsUnchangedInputs = true,
        .sunAt = SkyDirectionAt,
        .symbol = "T_sky",
        .rule = ShadeCompareRule,
        .ruleNote = "one storage quantum with fp16 or unorm8 storage",
        .sceneFields = kShadeSkySceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallShadeSky(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                    StageCallRecord& record) {
    const ShadeParams p = MakeShadeSkyParams(sc);
    return TimedStage(Stage::ShadeSky, backend, host, record,
                      [&] { return backend.ShadeSky(p, *io.Current(Resource::Q), *io.Current(Resource::TSky)); });
}

}  // namespace cb
