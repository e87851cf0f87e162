#include "core/stages/ca/Ca.h"

#include <limits>
#include <optional>
#include <vector>

#include "core/math/Random.h"
#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

constexpr int64_t kI32Min = std::numeric_limits<int32_t>::min();
constexpr int64_t kI32Max = std::numeric_limits<int32_t>::max();
constexpr std::string_view kCaKeys[] = {"seed", "hum0", "act0", "p_ext", "p_hum", "p_act", "wind_shift"};

}  // namespace

// Reads ca; the wind shift stays as written (one pair or nz pairs) until the size checks passed.
void ReadCa(const Json& root, Validator& check, std::optional<uint32_t> nz, CaSettings& ca) {
    const Json* section = check.Section(root, "", "ca", kCaKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "seed")) {
        if (auto n = check.Integer(*v, "ca.seed", 0, kU32Max)) ca.seed = uint32_t(*n);
    }
    const std::pair<std::string_view, double*> probabilities[] = {
        {"hum0", &ca.hum0}, {"act0", &ca.act0}, {"p_ext", &ca.pExt}, {"p_hum", &ca.pHum}, {"p_act", &ca.pAct}};
    for (auto [key, target] : probabilities) {
        if (const Json* v = Validator::Find(*section, key)) {
            if (auto d = check.Number(*v, JoinField("ca", key), kProbability)) *target = *d;
        }
    }
    const Json* shifts = Validator::Find(*section, "wind_shift");
    if (!shifts) return;
    if (!shifts->is_array()) {
        check.Fail("ca.wind_shift", "expected an array of [sx, sy] integer pairs, got " + Describe(*shifts));
        return;
    }
    if (nz && shifts->size() != 0 && shifts->size() != 1 && shifts->size() != *nz) {
        check.Fail("ca.wind_shift", "expected 1 pair (for every slice) or nz = " + std::to_string(*nz) +
                                        " pairs, got " + std::to_string(shifts->size()));
    }
    ca.windShift.clear();
    for (size_t i = 0; i < shifts->size(); ++i) {
        if (auto pair = check.Integers<2>((*shifts)[i], IndexField("ca.wind_shift", i), kI32Min, kI32Max))
            ca.windShift.push_back(SliceShift{int32_t((*pair)[0]), int32_t((*pair)[1])});
    }
}

}  // namespace cb::scene_io

namespace cb {

CaInitParams MakeCaInitParams(const Scene& sc) {
    return {sc.ca.seed, QuantizeProbability(sc.ca.hum0), QuantizeProbability(sc.ca.act0)};
}

CaStepParams MakeCaStepParams(const Scene& sc, uint32_t step) {
    CaStepParams p;
    p.seed = sc.ca.seed;
    p.step = step;
    p.qExt = QuantizeProbability(sc.ca.pExt);
    p.qHum = QuantizeProbability(sc.ca.pHum);
    p.qAct = QuantizeProbability(sc.ca.pAct);
    return p;
}

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kCaSceneFields[] = {"ca"};

constexpr std::string_view kCaSceneKeys[] = {"ca"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeCa() {
    static const StageDescriptor descriptor{
        .stage = Stage::Ca,
        .section = "ca",
        .sceneKeys = kCaSceneKeys,
        .readSettings =
            [](const scene_io::Json& root, scene_io::Validator& check, const Extent3* grid, Scene& scene) {
                scene_io::ReadCa(root, check, grid ? std::optional(grid->nz) : std::nullopt, scene.ca);
            },
        .reads = {Resource::Region, Resource::Hum, Resource::Act, Resource::Cld},
        .writes = {Resource::Hum, Resource::Act, Resource::Cld},
        .advancesState = true,
        .shareCount = SharesOfSlicesK,
        .symbol = "cld",
        .rule = BitExactRule,
        .sceneFields = kCaSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallCa(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
              StageCallRecord& record) {
    CaStepParams params = MakeCaStepParams(sc, host.step);
    std::vector<int32_t> shiftX, shiftY;
    if (sc.ca.HasWind())
        for (const SliceShift& s : sc.ca.windShift) shiftX.push_back(s.sx), shiftY.push_back(s.sy);
    params.shiftX = shiftX;
    params.shiftY = shiftY;
    params.slices = host.slices;
    const ConstCaFields in{io.Current(Resource::Hum), io.Current(Resource::Act), io.Current(Resource::Cld)};
    const CaFields out{io.Next(Resource::Hum), io.Next(Resource::Act), io.Next(Resource::Cld)};
    return TimedStage(Stage::Ca, backend, host, record,
                      [&] { return backend.CaStep(params, in, *io.Current(Resource::Region), out); });
}

}  // namespace cb
