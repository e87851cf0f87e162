#include "core/stages/region/Region.h"

#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

constexpr int64_t kSeed64Max = int64_t(1) << 53;
// clang-format off
constexpr std::string_view kEllipsoidKeys[] = {
    "seed",              "target_count", "density_adaption", "size_mean",    "size_variance", "lifetime_mean",
    "lifetime_variance", "shrink_steps", "margin",           "height_range", "wind",          "jitter",
    "placed"};
constexpr std::string_view kPlacedKeys[] = {
    "name", "center", "semi_axes", "yaw_deg", "start", "lifetime", "persistent", "keyframes"};
// clang-format on
constexpr std::string_view kPlacedKeyframeKeys[] = {"step", "center"};
constexpr std::string_view kWindGridKeys[] = {"grid", "vectors"};
// A placed ellipsoid's centre and semi-axes, in voxels: within a float's exact integers' reach of the grid.
constexpr double kPlacedReach = 1e9;
constexpr Range kPlacedCentre{.lo = -kPlacedReach, .hi = kPlacedReach};
constexpr Range kPlacedSemiAxis{.lo = 0, .loOpen = true, .hi = kPlacedReach};
constexpr size_t kMostPlaced = 100000;

void ReadWind(const Json& value, Validator& check, EllipsoidWind& wind) {
    const std::string field = "ellipsoids.wind";
    if (value.is_array()) {
        if (auto v = check.Numbers<2>(value, field, kFinite)) wind.vector = *v;
        return;
    }
    if (!value.is_object()) {
        check.Fail(field,
                   "expected [wx, wy] or {\"grid\": [gx, gy], \"vectors\": [[wx, wy], ...]}, got " + Describe(value));
        return;
    }
    check.CheckKeys(value, field, kWindGridKeys);
    const Json* grid = Validator::Find(value, "grid");
    const Json* vectors = Validator::Find(value, "vectors");
    if (!grid) check.Fail(field + ".grid", "required field is missing");
    if (!vectors) check.Fail(field + ".vectors", "required field is missing");

    std::optional<std::array<int64_t, 2>> size;
    if (grid) size = check.Integers<2>(*grid, field + ".grid", 1, kU32Max);
    if (!vectors) return;
    if (!vectors->is_array()) {
        check.Fail(field + ".vectors", "expected an array of [wx, wy] pairs, got " + Describe(*vectors));
        return;
    }
    if (size) {
        const uint64_t expected = uint64_t((*size)[0]) * uint64_t((*size)[1]);
        if (vectors->size() != expected) {
            check.Fail(field + ".vectors", "expected " + std::to_string(expected) + " pairs (grid " +
                                               std::to_string((*size)[0]) + " x " + std::to_string((*size)[1]) +
                                               "), got " + std::to_string(vectors->size()));
        }
        wind.gridNx = uint32_t((*size)[0]);
        wind.gridNy = uint32_t((*size)[1]);
    }
    wind.grid.clear();
    for (size_t i = 0; i < vectors->size(); ++i) {
        if (auto v = check.Numbers<2>((*vectors)[i], IndexField(field + ".vectors", i), kFinite))
            wind.grid.push_back(*v);
    }
}

// Keyframes {step, center} in strictly increasing step order; nullopt (with the errors reported) when any is wrong.
std::optional<std::vector<PlacedKeyframe>> ReadPlacedKeyframes(const Json& value, Validator& check,
                                                               const std::string& field) {
    if (!value.is_array() || value.empty()) {
        check.Fail(field, "expected a non-empty array of keyframes {\"step\", \"center\"}, got " + Describe(value));
        return std::nullopt;
    }
    std::vector<PlacedKeyframe> keyframes;
    bool ok = true;
    for (size_t i = 0; i < value.size(); ++i) {
        const Json& k = value[i];
        const std::string at = IndexField(field, i);
        if (!k.is_object()) {
            check.Fail(at, "expected a keyframe object {\"step\", \"center\"}, got " + Describe(k));
            ok = false;
            continue;
        }
        check.CheckKeys(k, at, kPlacedKeyframeKeys);
        std::optional<int64_t> step;
        std::optional<std::array<double, 3>> center;
        if (const Json* v = Validator::Find(k, "step"))
            step = check.Integer(*v, JoinField(at, "step"), 0, kU32Max);
        else
            check.Fail(JoinField(at, "step"), "required field is missing");
        if (const Json* v = Validator::Find(k, "center"))
            center = check.Numbers<3>(*v, JoinField(at, "center"), kPlacedCentre);
        else
            check.Fail(JoinField(at, "center"), "required field is missing");
        if (!step || !center) {
            ok = false;
            continue;
        }
        const std::optional<uint32_t> previous =
            keyframes.empty() ? std::nullopt : std::optional(keyframes.back().step);
        if (!check.StepAfterPrevious(JoinField(at, "step"), previous, uint32_t(*step))) {
            ok = false;
            continue;
        }
        keyframes.push_back({uint32_t(*step), *center});
    }
    if (!ok) return std::nullopt;
    return keyframes;
}

// One hand-placed ellipsoid (SPEC 17); nullopt (with the errors reported) when any field is wrong.
std::optional<PlacedEllipsoid> ReadPlaced(const Json& value, Validator& check, const std::string& field) {
    if (!value.is_object()) {
        check.Fail(field,
                   "expected a placed ellipsoid object {\"center\" or \"keyframes\", \"semi_axes\", "
                   "\"lifetime\" or \"persistent\", ...}, got " +
                       Describe(value));
        return std::nullopt;
    }
    const size_t errorsBefore = check.ErrorCount();
    check.CheckKeys(value, field, kPlacedKeys);
    auto at = [&](std::string_view key) { return JoinField(field, key); };
    auto find = [&](std::string_view key) { return Validator::Find(value, key); };
    PlacedEllipsoid p;
    if (const Json* v = find("name")) {
        if (auto name = check.String(*v, at("name"))) p.name = *name;
    }
    const Json* center = find("center");
    const Json* keyframes = find("keyframes");
    if (center && keyframes)
        check.Fail(at("center"), "cannot be combined with keyframes (the keyframes give the centre)");
    else if (!center && !keyframes)
        check.Fail(at("center"), "required field is missing (or \"keyframes\")");
    else if (center) {
        if (auto c = check.Numbers<3>(*center, at("center"), kPlacedCentre)) p.center = *c;
    } else if (auto k = ReadPlacedKeyframes(*keyframes, check, at("keyframes"))) {
        p.keyframes = std::move(*k);
        p.center = p.keyframes.front().center;
    }
    if (const Json* v = find("semi_axes")) {
        if (auto a = check.Numbers<3>(*v, at("semi_axes"), kPlacedSemiAxis)) p.semiAxes = *a;
    } else {
        check.Fail(at("semi_axes"), "required field is missing");
    }
    if (const Json* v = find("yaw_deg")) {
        if (auto d = check.Number(*v, at("yaw_deg"), Range{.lo = -360, .hi = 360})) p.yawDeg = *d;
    }
    if (const Json* v = find("start")) {
        if (auto n = check.Integer(*v, at("start"), 0, kU32Max)) p.start = uint32_t(*n);
    }
    const Json* lifetime = find("lifetime");
    std::optional<bool> persistent;
    if (const Json* v = find("persistent")) persistent = check.Boolean(*v, at("persistent"));
    if (lifetime && persistent.value_or(false)) {
        check.Fail(at("persistent"), "cannot be combined with lifetime (a persistent ellipsoid never expires)");
    } else if (lifetime) {
        if (auto n = check.Integer(*lifetime, at("lifetime"), 1, kU32Max)) p.lifetime = uint32_t(*n);
    } else if (persistent.has_value() && !*persistent) {
        check.Fail(at("lifetime"), "required field is missing (\"persistent\" is false)");
    } else if (!persistent.has_value() && !find("persistent")) {
        check.Fail(at("lifetime"), "required field is missing (or \"persistent\": true)");
    }
    if (check.ErrorCount() != errorsBefore) return std::nullopt;
    return p;
}

void ReadPlacedList(const Json& value, Validator& check, std::vector<PlacedEllipsoid>& placed) {
    const std::string field = "ellipsoids.placed";
    if (!value.is_array()) {
        check.Fail(field, "expected an array of placed ellipsoids, got " + Describe(value));
        return;
    }
    if (value.size() > kMostPlaced) {
        check.Fail(field, "at most " + std::to_string(kMostPlaced) + " placed ellipsoids, got " +
                              std::to_string(value.size()));
        return;
    }
    placed.clear();
    for (size_t i = 0; i < value.size(); ++i)
        if (auto p = ReadPlaced(value[i], check, IndexField(field, i))) placed.push_back(std::move(*p));
}

}  // namespace

void ReadEllipsoids(const Json& root, Validator& check, EllipsoidSettings& e) {
    const Json* section = check.Section(root, "", "ellipsoids", kEllipsoidKeys);
    if (!section) return;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    auto field = [](std::string_view key) { return JoinField("ellipsoids", key); };

    if (const Json* v = find("seed")) {
        if (auto n = check.Integer(*v, field("seed"), 0, kSeed64Max)) e.seed = uint64_t(*n);
    }
    if (const Json* v = find("target_count")) {
        if (auto n = check.Integer(*v, field("target_count"), 0, 100000)) e.targetCount = uint32_t(*n);
    }
    if (const Json* v = find("density_adaption")) {
        if (auto n = check.Integer(*v, field("density_adaption"), 0, 100000)) e.densityAdaption = uint32_t(*n);
    }
    // Each variance must not exceed its mean; the message names whichever of the two the file gave.
    bool sizeMeanOk = true, sizeVarianceOk = true;
    if (const Json* v = find("size_mean")) {
        auto a = check.Numbers<3>(*v, field("size_mean"), kPositive);
        if (a) e.sizeMean = *a;
        sizeMeanOk = a.has_value();
    }
    const Json* sizeVariance = find("size_variance");
    if (sizeVariance) {
        auto a = check.Numbers<3>(*sizeVariance, field("size_variance"), kNonNegative);
        if (a) e.sizeVariance = *a;
        sizeVarianceOk = a.has_value();
    }
    for (size_t i = 0; sizeMeanOk && sizeVarianceOk && i < 3; ++i) {
        if (e.sizeVariance[i] <= e.sizeMean[i]) continue;
        const std::string index = IndexField("", i);  // "[i]"
        if (sizeVariance)
            check.Fail(field("size_variance") + index, "must be <= size_mean" + index + " (" +
                                                           FormatNumber(e.sizeMean[i]) + "), got " +
                                                           FormatNumber(e.sizeVariance[i]));
        else
            check.Fail(field("size_mean") + index, "must be >= size_variance" + index + " (" +
                                                       FormatNumber(e.sizeVariance[i]) + "), got " +
                                                       FormatNumber(e.sizeMean[i]));
    }
    bool lifetimeMeanOk = true, lifetimeVarianceOk = true;
    if (const Json* v = find("lifetime_mean")) {
        auto d = check.Number(*v, field("lifetime_mean"), Range{.lo = 1});
        if (d) e.lifetimeMean = *d;
        lifetimeMeanOk = d.has_value();
    }
    const Json* lifetimeVariance = find("lifetime_variance");
    if (lifetimeVariance) {
        auto d = check.Number(*lifetimeVariance, field("lifetime_variance"), kNonNegative);
        if (d) e.lifetimeVariance = *d;
        lifetimeVarianceOk = d.has_value();
    }
    if (lifetimeMeanOk && lifetimeVarianceOk && e.lifetimeVariance >= e.lifetimeMean) {
        if (lifetimeVariance)
            check.Fail(field("lifetime_variance"), "must be < lifetime_mean (" + FormatNumber(e.lifetimeMean) +
                                                       "), got " + FormatNumber(e.lifetimeVariance));
        else
            check.Fail(field("lifetime_mean"), "must be > lifetime_variance (" + FormatNumber(e.lifetimeVariance) +
                                                   "), got " + FormatNumber(e.lifetimeMean));
    }
    if (const Json* v = find("shrink_steps")) {
        if (auto n = check.Integer(*v, field("shrink_steps"), 0, kU32Max)) e.shrinkSteps = uint32_t(*n);
    }
    if (const Json* v = find("margin")) {
        if (auto d = check.Number(*v, field("margin"), kNonNegative)) e.margin = *d;
    }
    if (const Json* v = find("height_range")) {
        if (auto a = check.Numbers<2>(*v, field("height_range"), kProbability)) {
            if ((*a)[0] > (*a)[1])
                check.Fail(field("height_range"), "lo must be <= hi, got " + Describe(*v));
            else
                e.heightRange = *a;
        }
    }
    if (const Json* v = find("wind")) ReadWind(*v, check, e.wind);
    if (const Json* v = find("jitter")) {
        if (auto d = check.Number(*v, field("jitter"), kNonNegative)) e.jitter = *d;
    }
    if (const Json* v = find("placed")) ReadPlacedList(*v, check, e.placed);
}

}  // namespace cb::scene_io

namespace cb {
namespace {

// SPEC 2: the region weight may round either way at a quantisation boundary.
CompareRule RegionRule(const Scene&) { return {CompareRule::Kind::Quantised, 1, 0.005}; }

}  // namespace

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kRegionSceneFields[] = {"ellipsoids", "ca.seed"};

constexpr std::string_view kRegionSceneKeys[] = {"ellipsoids"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeRegion() {
    static const StageDescriptor descriptor{
        .stage = Stage::Region,
        .section = "ellipsoids",
        .sceneKeys = kRegionSceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3*,
                           Scene& scene) { scene_io::ReadEllipsoids(root, check, scene.ellipsoids); },
        .writes = {Resource::Region},
        .shareCount = SharesOfSlicesK,
        .symbol = "R",
        .rule = RegionRule,
        .sceneFields = kRegionSceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallRegion(Backend& backend, const Scene&, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record) {
    return TimedStage(Stage::Region, backend, host, record,
                      [&] { return backend.Region(host.raster, *io.Current(Resource::Region), host.slices); });
}

}  // namespace cb
