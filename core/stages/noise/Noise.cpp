#include "core/stages/noise/Noise.h"

#include <string>
#include <string_view>

#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kNoiseKeys[] = {"seed",       "basis",      "frequency", "octaves",  "gain",
                                           "lacunarity", "turbulence", "height_a",  "height_b", "towers",
                                           "threshold",  "detail",     "coverage",  "drift"};
constexpr std::string_view kTowerKeys[] = {"center", "sigma", "amplitude"};
constexpr std::string_view kDetailKeys[] = {"size", "basis",      "frequency",  "octaves",
                                            "gain", "lacunarity", "turbulence", "strength"};
constexpr std::string_view kCoverageKeys[] = {"coverage", "density", "frequency", "octaves", "gain"};

// Lattice frequencies (cells across the grid, or the detail volume) at the
// highest octave stay at most this, so float lattice coordinates keep 12
// fractional bits and the simplex hash's integers stay small.
constexpr int64_t kMaxLatticeFrequency = 4096;
constexpr size_t kMaxTowers = 1024;
constexpr double kMaxVoxels = 1e6;  // tower centres, sizes and drift, in voxels
// The threshold c and the erosion strength s divide by 1 - c and 1 - s d in
// float: at most 0.99, so the divisor never rounds to 0.
constexpr double kMaxFraction = 0.99;
// A tower's sigma, so 1 / sigma^2 stays a modest float.
constexpr double kMinSigma = 1e-3;

// fBm fields (basis, octaves, gain, lacunarity, turbulence) of `section` into `fbm`.
void ReadFbm(const Json& section, std::string_view parent, Validator& check, FbmSettings& fbm) {
    auto field = [&](std::string_view key) { return JoinField(parent, key); };
    if (const Json* v = Validator::Find(section, "basis")) {
        if (auto b = check.Choice(*v, field("basis"), kNoiseBasisNames)) fbm.basis = *b;
    }
    if (const Json* v = Validator::Find(section, "octaves")) {
        if (auto n = check.Integer(*v, field("octaves"), 1, 16)) fbm.octaves = uint32_t(*n);
    }
    if (const Json* v = Validator::Find(section, "gain")) {
        if (auto d = check.Number(*v, field("gain"), Range{.lo = 0, .loOpen = true, .hi = 1})) fbm.gain = *d;
    }
    if (const Json* v = Validator::Find(section, "lacunarity")) {
        if (auto n = check.Integer(*v, field("lacunarity"), 2, 8)) fbm.lacunarity = uint32_t(*n);
    }
    if (const Json* v = Validator::Find(section, "turbulence")) {
        if (auto b = check.Boolean(*v, field("turbulence"))) fbm.turbulence = *b;
    }
}

// The checks that tie an fBm to its lattice frequencies: the highest octave's
// frequency is bounded, and simplex tiles only on periods that are multiples of 3.
void CheckFrequencies(const FbmSettings& fbm, const uint32_t* frequency, size_t axes, std::string_view field,
                      Validator& check) {
    // The real lacunarity^(octaves - 1) (it was capped at the first power past the bound, so the message said
    // "1 x 8192" for any octaves from 14 on), at most 8^15 = 2^45, exact in 64 bits; its product with the
    // frequency is compared in double, exact up to 2^53 and only rounded far past the bound.
    uint64_t multiplier = 1;
    for (uint32_t o = 1; o < fbm.octaves; ++o) multiplier *= fbm.lacunarity;
    for (size_t a = 0; a < axes; ++a) {
        const std::string name = axes > 1 ? IndexField(field, a) : std::string(field);
        const double product = double(frequency[a]) * double(multiplier);
        if (product > double(kMaxLatticeFrequency)) {
            check.Fail(name, "times lacunarity^(octaves - 1) must be at most " + std::to_string(kMaxLatticeFrequency) +
                                 " lattice cells, got " + std::to_string(frequency[a]) + " x " +
                                 std::to_string(multiplier));
            return;
        }
        if (fbm.basis == NoiseBasis::Simplex && frequency[a] % 3 != 0) {
            check.Fail(name,
                       "must be a multiple of 3 with the simplex basis (its lattice tiles only on such "
                       "periods), got " +
                           std::to_string(frequency[a]));
            return;
        }
    }
}

void ReadTowers(const Json& list, Validator& check, std::vector<NoiseTower>& towers) {
    const std::string field = "noise.towers";
    if (!list.is_array()) {
        check.Fail(field, "expected an array of {\"center\", \"sigma\", \"amplitude\"} objects, got " + Describe(list));
        return;
    }
    if (list.size() > kMaxTowers) {
        check.Fail(field, "at most " + std::to_string(kMaxTowers) + " towers, got " + std::to_string(list.size()));
        return;
    }
    towers.clear();
    const Range position{.lo = -kMaxVoxels, .hi = kMaxVoxels};
    const Range size{.lo = kMinSigma, .hi = kMaxVoxels};
    for (size_t n = 0; n < list.size(); ++n) {
        const std::string tf = IndexField(field, n);
        const Json& item = list[n];
        if (!item.is_object()) {
            check.Fail(tf, "expected a tower object, got " + Describe(item));
            continue;
        }
        check.CheckKeys(item, tf, kTowerKeys);
        NoiseTower tower;
        bool ok = true;
        if (const Json* v = Validator::Find(item, "center")) {
            auto a = check.Numbers<3>(*v, JoinField(tf, "center"), position);
            if (a) tower.center = *a;
            ok = ok && a.has_value();
        } else {
            check.Fail(JoinField(tf, "center"), "required field is missing");
            ok = false;
        }
        if (const Json* v = Validator::Find(item, "sigma")) {
            auto a = check.Numbers<3>(*v, JoinField(tf, "sigma"), size);
            if (a) tower.sigma = *a;
            ok = ok && a.has_value();
        }
        if (const Json* v = Validator::Find(item, "amplitude")) {
            auto d = check.Number(*v, JoinField(tf, "amplitude"), Range{.lo = -100, .hi = 100});
            if (d) tower.amplitude = *d;
            ok = ok && d.has_value();
        }
        if (ok) towers.push_back(tower);
    }
}

void ReadDetail(const Json& root, Validator& check, NoiseDetail& detail) {
    const Json* section = check.Section(root, "noise", "detail", kDetailKeys);
    if (!section) return;
    detail.enabled = true;
    if (const Json* v = Validator::Find(*section, "size")) {
        if (auto n = check.Integer(*v, "noise.detail.size", 1, 128)) detail.size = uint32_t(*n);
    }
    bool frequencyOk = true;
    if (const Json* v = Validator::Find(*section, "frequency")) {
        auto n = check.Integer(*v, "noise.detail.frequency", 1, kMaxLatticeFrequency);
        if (n) detail.frequency = uint32_t(*n);
        frequencyOk = n.has_value();
    }
    const size_t before = check.ErrorCount();
    ReadFbm(*section, "noise.detail", check, detail.fbm);
    if (const Json* v = Validator::Find(*section, "strength")) {
        if (auto d = check.Number(*v, "noise.detail.strength", Range{.lo = 0, .hi = kMaxFraction}))
            detail.strength = *d;
    }
    if (frequencyOk && check.ErrorCount() == before)
        CheckFrequencies(detail.fbm, &detail.frequency, 1, "noise.detail.frequency", check);
}

}  // namespace

void ReadCoverage(const Json& parent, std::string_view parentField, std::string_view key, Validator& check,
                  NoiseCoverage& coverage) {
    const Json* section = check.Section(parent, parentField, key, kCoverageKeys);
    if (!section) return;
    coverage.enabled = true;
    const std::string path = std::string(parentField) + "." + std::string(key) + ".";
    auto field = [&](const char* name) { return path + name; };
    if (const Json* v = Validator::Find(*section, "coverage")) {
        if (auto d = check.Number(*v, field("coverage"), kProbability)) coverage.coverage = *d;
    }
    if (const Json* v = Validator::Find(*section, "density")) {
        if (auto d = check.Number(*v, field("density"), Range{.lo = 0, .hi = 1e6})) coverage.density = *d;
    }
    if (const Json* v = Validator::Find(*section, "frequency")) {
        if (auto n = check.Integers<2>(*v, field("frequency"), 1, kMaxLatticeFrequency))
            coverage.frequency = {uint32_t((*n)[0]), uint32_t((*n)[1])};
    }
    if (const Json* v = Validator::Find(*section, "octaves")) {
        if (auto n = check.Integer(*v, field("octaves"), 1, 16)) coverage.octaves = uint32_t(*n);
    }
    if (const Json* v = Validator::Find(*section, "gain")) {
        if (auto d = check.Number(*v, field("gain"), Range{.lo = 0, .loOpen = true, .hi = 1})) coverage.gain = *d;
    }
    const FbmSettings map{NoiseBasis::Perlin, coverage.octaves, coverage.gain, 2, false};
    CheckFrequencies(map, coverage.frequency.data(), 2, field("frequency"), check);
}

void ReadNoise(const Json& root, Validator& check, NoiseSettings& noise) {
    const Json* section = check.Section(root, "", "noise", kNoiseKeys);
    if (!section) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    if (const Json* v = find("seed")) {
        if (auto n = check.Integer(*v, "noise.seed", 0, kU32Max)) noise.seed = uint32_t(*n);
    }
    bool frequencyOk = true;
    if (const Json* v = find("frequency")) {
        auto n = check.Integers<3>(*v, "noise.frequency", 1, kMaxLatticeFrequency);
        if (n) noise.frequency = {uint32_t((*n)[0]), uint32_t((*n)[1]), uint32_t((*n)[2])};
        frequencyOk = n.has_value();
    }
    const size_t before = check.ErrorCount();
    ReadFbm(*section, "noise", check, noise.fbm);
    if (frequencyOk && check.ErrorCount() == before)
        CheckFrequencies(noise.fbm, noise.frequency.data(), 3, "noise.frequency", check);
    if (const Json* v = find("height_a")) {
        if (auto d = check.Number(*v, "noise.height_a", Range{.lo = 0, .hi = 1000})) noise.heightA = *d;
    }
    if (const Json* v = find("height_b")) {
        if (auto d = check.Number(*v, "noise.height_b", Range{.lo = 0, .hi = 1000})) noise.heightB = *d;
    }
    if (const Json* v = find("towers")) ReadTowers(*v, check, noise.towers);
    if (const Json* v = find("threshold")) {
        if (auto d = check.Number(*v, "noise.threshold", Range{.lo = 0, .hi = kMaxFraction})) noise.threshold = *d;
    }
    ReadDetail(*section, check, noise.detail);
    ReadCoverage(*section, "noise", "coverage", check, noise.coverage);
    if (const Json* v = find("drift")) {
        if (auto a = check.Numbers<3>(*v, "noise.drift", Range{.lo = -kMaxVoxels, .hi = kMaxVoxels})) noise.drift = *a;
    }
}

}  // namespace cb::scene_io

namespace cb {
namespace {

// SPEC 10a.
CompareRule NoiseRule(const Scene&) { return {CompareRule::Kind::Absolute, 1e-5}; }

// Noise reads nothing: static noise is made once, drifting noise every step (SPEC 14).
bool NoiseAnimated(const Scene& scene) { return scene.noise.Animated(); }

}  // namespace

NoiseParams MakeNoiseParams(const Scene& sc, uint32_t step) { return {step, &sc.noise, sc.grid.size}; }

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kNoiseSceneFields[] = {"noise"};

constexpr std::string_view kNoiseSceneKeys[] = {"noise"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeNoise() {
    static const StageDescriptor descriptor{
        .stage = Stage::Noise,
        .section = "noise",
        .sceneKeys = kNoiseSceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadNoise(root, check, scene.noise); },
        .writes = {Resource::Q},
        .skipsUnchangedInputs = true,
        .dependsOnStep = NoiseAnimated,
        .symbol = "q",
        .rule = NoiseRule,
        .sceneFields = kNoiseSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallNoise(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                 StageCallRecord& record) {
    const NoiseParams p = MakeNoiseParams(sc, host.step);
    return TimedStage(Stage::Noise, backend, host, record, [&] { return backend.Noise(p, *io.Current(Resource::Q)); });
}

}  // namespace cb
