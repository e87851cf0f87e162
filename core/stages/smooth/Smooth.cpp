#include "core/stages/smooth/Smooth.h"

#include "core/scene/SceneReaders.h"

namespace cb {
namespace {

std::vector<std::string> SmoothRadiusValues() {
    std::vector<std::string> values;
    for (int r = 0; r <= kMaxSmoothRadius; ++r) values.push_back(std::to_string(r));
    return values;
}
constexpr ChoiceSetting kSmoothRadius{"smooth.radius", SmoothRadiusValues,
                                      [](const Scene& s) { return std::to_string(s.smooth.radius); }};
constexpr ChoiceSetting kSmoothChoices[] = {kSmoothRadius};

}  // namespace
}  // namespace cb

namespace cb::scene_io {
namespace {

constexpr std::string_view kSmoothKeys[] = {"radius"};

}  // namespace

void ReadSmooth(const Json& root, Validator& check, SmoothSettings& smooth) {
    const Json* section = check.Section(root, "", "smooth", kSmoothKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "radius")) {
        if (auto n = check.Integer(*v, kSmoothRadius.path, 0, kMaxSmoothRadius)) smooth.radius = int(*n);
    }
}

}  // namespace cb::scene_io

namespace cb {

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kSmoothSceneFields[] = {"smooth"};

constexpr std::string_view kSmoothSceneKeys[] = {"smooth"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeSmooth() {
    static const StageDescriptor descriptor{
        .stage = Stage::Smooth,
        .section = "smooth",
        .sceneKeys = kSmoothSceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadSmooth(root, check, scene.smooth); },
        .reads = {Resource::Cld},
        .writes = {Resource::Q},
        .shareCount = SharesOfSlicesK,
        .symbol = "q",
        .rule = BitExactRule,
        .choices = kSmoothChoices,
        .sceneFields = kSmoothSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallSmooth(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record) {
    return TimedStage(Stage::Smooth, backend, host, record, [&] {
        return backend.Smooth(sc.smooth.radius, *io.Current(Resource::Cld), *io.Current(Resource::Q), host.slices);
    });
}

}  // namespace cb
