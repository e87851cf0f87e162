// Readers of the simulation sections (grid, stages, ca, ellipsoids, smooth,
// density) and of the whole scene.
#include "core/scene/SceneReaders.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string_view>
#include <utility>
#include <vector>

namespace cb::scene_io {
namespace {

constexpr int64_t kI32Min = std::numeric_limits<int32_t>::min();
constexpr int64_t kI32Max = std::numeric_limits<int32_t>::max();
constexpr int64_t kSeed64Max = int64_t(1) << 53;

constexpr Stage kDefaultStages[] = {Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density};

constexpr std::string_view kTopKeys[] = {
    "name", "description", "grid",  "steps", "warmup_steps", "stages", "ca",    "ellipsoids", "smooth", "density",
    "sun",  "lighting",    "phase", "shade", "shadow",       "render", "march", "lightning",  "noise"};
constexpr std::string_view kGridKeys[] = {"size", "voxel_size", "origin"};
constexpr std::string_view kCaKeys[] = {"seed", "hum0", "act0", "p_ext", "p_hum", "p_act", "wind_shift"};
// clang-format off
constexpr std::string_view kEllipsoidKeys[] = {
    "seed",              "target_count", "density_adaption", "size_mean",    "size_variance", "lifetime_mean",
    "lifetime_variance", "shrink_steps", "margin",           "height_range", "wind",          "jitter"};
// clang-format on
constexpr std::string_view kWindGridKeys[] = {"grid", "vectors"};
constexpr std::string_view kSmoothKeys[] = {"radius"};
constexpr std::string_view kDensityKeys[] = {"tile", "band"};

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

}  // namespace

// Returns true when grid.size is present and valid.
bool ReadGrid(const Json& root, Validator& check, GridSettings& grid) {
    const Json* section = Validator::Find(root, "grid");
    if (!section) {
        check.Fail("grid.size", "required field is missing");
        return false;
    }
    section = check.Section(root, "", "grid", kGridKeys);
    if (!section) return false;

    bool sizeOk = false;
    if (const Json* size = Validator::Find(*section, "size")) {
        if (auto n = check.Integers<3>(*size, "grid.size", 1, kU32Max)) {
            grid.size = Extent3{uint32_t((*n)[0]), uint32_t((*n)[1]), uint32_t((*n)[2])};
            sizeOk = true;
        }
    } else {
        check.Fail("grid.size", "required field is missing");
    }
    if (const Json* v = Validator::Find(*section, "voxel_size")) {
        if (auto d = check.Number(*v, "grid.voxel_size", kSinglePositive)) grid.voxelSize = *d;
    }
    if (const Json* v = Validator::Find(*section, "origin")) {
        if (auto a = check.Numbers<3>(*v, "grid.origin", kFinite)) grid.origin = *a;
    }
    return sizeOk;
}

bool ReadStages(const Json& root, Validator& check, StageSet& stages) {
    const Json* list = Validator::Find(root, "stages");
    if (!list) {
        for (Stage stage : kDefaultStages) stages.Add(stage);
        return true;
    }
    if (!list->is_array()) {
        check.Fail("stages", "expected an array of stage names, got " + Describe(*list));
        return false;
    }
    if (list->empty()) {
        check.Fail("stages", "must name at least one stage, got []");
        return false;
    }
    std::vector<std::string_view> known;
    for (Stage stage : kAllStages) known.push_back(StageName(stage));

    bool allOk = true;
    for (size_t i = 0; i < list->size(); ++i) {
        const std::string field = IndexField("stages", i);
        auto name = check.String((*list)[i], field);
        if (!name) {
            allOk = false;
            continue;
        }
        std::optional<Stage> stage = ParseStage(*name);
        if (!stage) {
            std::string all;
            for (std::string_view k : known) all += (all.empty() ? "" : ", ") + std::string(k);
            check.Fail(field, "unknown stage " + Quote(*name) + Suggestion(*name, known) + "; known: " + all);
            allOk = false;
        } else if (stages.Has(*stage)) {
            check.Fail(field, "duplicate stage " + Quote(*name));
            allOk = false;
        } else {
            stages.Add(*stage);
        }
    }
    return allOk;
}

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
}

void ReadSmooth(const Json& root, Validator& check, SmoothSettings& smooth) {
    const Json* section = check.Section(root, "", "smooth", kSmoothKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "radius")) {
        if (auto n = check.Integer(*v, "smooth.radius", 0, 2)) smooth.radius = int(*n);
    }
}

// `grid` is the grid's size when it was valid. Tile and band counts are CeilDiv(edge, tile), computed in 32 bits as
// (edge + tile - 1) / tile: tile + edge - 1 must fit, so tile is at most 2^32 - the edge it divides.
void ReadDensity(const Json& root, Validator& check, DensitySettings& density, const Extent3* grid) {
    const Json* section = check.Section(root, "", "density", kDensityKeys);
    if (!section) return;
    auto read = [&](std::string_view key, uint32_t edge, std::string_view edgeText, uint32_t& target) {
        const Json* v = Validator::Find(*section, key);
        if (!v) return;
        const std::string field = JoinField("density", key);
        auto n = check.Integer(*v, field, 1, kU32Max);
        if (!n) return;
        const int64_t most = kU32Max + 1 - int64_t(edge);
        if (*n > most) {
            check.Fail(field, "must be at most " + std::to_string(most) + " (2^32 - " + std::string(edgeText) + " " +
                                  std::to_string(edge) + ", so the count fits 32 bits), got " + Describe(*v));
            return;
        }
        target = uint32_t(*n);
    };
    read("tile", grid ? std::max(grid->nx, grid->ny) : 1, "the grid's longer horizontal edge", density.tile);
    read("band", grid ? grid->nz : 1, "the grid's height", density.band);
}

SectionsRead ReadSceneSections(const Json& root, const std::string& label, Validator& check, Scene& scene) {
    SectionsRead sections;
    check.CheckKeys(root, "", kTopKeys);

    // The name becomes the folder out/<name>: it follows kPathNameRule, and so must the file stem it defaults to.
    if (const Json* v = Validator::Find(root, "name")) {
        if (auto s = check.PathName(*v, "name")) scene.name = *s;
    } else {
        scene.name = std::filesystem::path(label).stem().string();
        if (!IsPathName(scene.name))
            check.Fail("name", "the default name " + QuoteShown(scene.name) + " (the file name) " +
                                   std::string(kPathNameRule) + "; set \"name\" in the file");
    }
    if (const Json* v = Validator::Find(root, "description")) check.String(*v, "description");

    sections.gridSize = ReadGrid(root, check, scene.grid);
    const bool sizeOk = sections.gridSize;

    bool stepsOk = true;
    if (const Json* v = Validator::Find(root, "steps")) {
        auto n = check.Integer(*v, "steps", 1, 10000000);
        if (n) scene.steps = uint32_t(*n);
        stepsOk = n.has_value();
        sections.steps = stepsOk;
    }
    if (const Json* v = Validator::Find(root, "warmup_steps")) {
        if (auto n = check.Integer(*v, "warmup_steps", 0, kU32Max)) {
            scene.warmupSteps = uint32_t(*n);
            if (stepsOk && scene.warmupSteps >= scene.steps)
                check.Fail("warmup_steps", "must be < steps (" + std::to_string(scene.steps) + "), got " +
                                               std::to_string(scene.warmupSteps));
        }
    }

    sections.stageList = ReadStages(root, check, scene.stages);
    ReadCa(root, check, sizeOk ? std::optional(scene.grid.size.nz) : std::nullopt, scene.ca);

    // The ellipsoid seed follows ca.seed unless given.
    scene.ellipsoids.seed = scene.ca.seed;
    ReadEllipsoids(root, check, scene.ellipsoids);

    ReadSmooth(root, check, scene.smooth);
    ReadDensity(root, check, scene.density, sizeOk ? &scene.grid.size : nullptr);

    ReadSun(root, check, scene.sun);
    ReadLighting(root, check, scene.lighting);
    ReadPhase(root, check, scene.phase);
    ReadShade(root, check, scene.shade);
    ReadShadow(root, check, scene.shadow);
    sections.cameras = ReadRender(root, check, scene.render);
    ReadSplat(root, check, scene.splat);
    ReadMarch(root, check, scene.stages, scene.march);
    ReadLightning(root, check, scene.lightning);
    ReadNoise(root, check, scene.noise);
    return sections;
}

}  // namespace cb::scene_io
