#include "core/pipeline/StageDescriptors.h"

#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/math/Shading.h"
#include "core/pipeline/ShadePlan.h"

namespace cb {

std::string_view ResourceName(Resource resource) {
    switch (resource) {
#define CB_RESOURCE_NAME(name, text, format, file) \
    case Resource::name:                           \
        return text;
        CB_RESOURCES(CB_RESOURCE_NAME)
#undef CB_RESOURCE_NAME
    }
    return "?";
}

std::string_view ResourceDumpStem(Resource resource) {
    switch (resource) {
#define CB_RESOURCE_STEM(name, text, format, file) \
    case Resource::name:                           \
        return file;
        CB_RESOURCES(CB_RESOURCE_STEM)
#undef CB_RESOURCE_STEM
    }
    return "";
}

BufferFormat ResourceFormat(Resource resource) {
    switch (resource) {
#define CB_RESOURCE_FORMAT(name, text, format, file) \
    case Resource::name:                             \
        return BufferFormat::format;
        CB_RESOURCES(CB_RESOURCE_FORMAT)
#undef CB_RESOURCE_FORMAT
    }
    return BufferFormat::F32;
}

bool IsPerCamera(Resource resource) { return resource == Resource::SplatImage || resource == Resource::MarchImage; }

Extent3 ResourceExtent(Resource resource, const Scene& scene) {
    const Extent3 grid = scene.grid.size;
    const uint32_t tile = scene.density.tile, band = scene.density.band;
    switch (resource) {
        case Resource::Region:
        case Resource::Hum:
        case Resource::Act:
        case Resource::Cld:
        case Resource::Q:
        case Resource::T:
            return grid;
        case Resource::ColumnSum:
        case Resource::Shadow:
            return {grid.nx, grid.ny, 1};
        case Resource::Tiles:
            return {CeilDiv(grid.nx, tile), CeilDiv(grid.ny, tile), 1};
        case Resource::Bands:
            return {CeilDiv(grid.nx, tile), CeilDiv(grid.ny, tile), CeilDiv(grid.nz, band)};
        case Resource::SplatImage:
        case Resource::MarchImage:
            return {3, scene.render.width, scene.render.height};
    }
    return grid;
}

namespace {

// A pixel value as rules state it: "2/255" where it is a whole number of 8-bit steps, "%g" otherwise.
std::string PixelValueText(double value) {
    char text[32];
    if (value * 255 == double(int(value * 255)))
        std::snprintf(text, sizeof text, "%d/255", int(value * 255));
    else
        std::snprintf(text, sizeof text, "%g", value);
    return text;
}

}  // namespace

std::string CompareRule::ToleranceText() const {
    if (kind == Kind::Image) return PixelValueText(tolerance);
    char text[32];
    std::snprintf(text, sizeof text, "%g", tolerance);
    return text;
}

std::string CompareRule::Text(std::string_view symbol) const {
    char text[96];
    std::string d = "|d";
    d.append(symbol).append("|");
    switch (kind) {
        case Kind::BitExact:
            return "bit-exact";
        case Kind::Absolute:
            std::snprintf(text, sizeof text, "%s <= %g", d.c_str(), tolerance);
            break;
        case Kind::Quantised:
            std::snprintf(text, sizeof text, "%s <= %g, <= %g %% differ", d.c_str(), tolerance, share * 100);
            break;
        case Kind::Codes:
            std::snprintf(text, sizeof text, "|d%s| <= %g %s code%s", std::string(symbol).c_str(), tolerance,
                          storage == StorageFormat::Fp16 ? "fp16" : "unorm8", tolerance == 1 ? "" : "s");
            break;
        case Kind::Image:
            std::snprintf(text, sizeof text, "%s on %g %%%s", ToleranceText().c_str(), 100 - share * 100,
                          std::isinf(limit) ? "" : (", " + PixelValueText(limit) + " max").c_str());
            break;
    }
    return text;
}

namespace {

CompareRule BitExact(const Scene&) { return {CompareRule::Kind::BitExact}; }

// SPEC 2: the region weight may round either way at a quantisation boundary.
CompareRule RegionRule(const Scene&) { return {CompareRule::Kind::Quantised, 1, 0.005}; }

// SPEC 6: 1e-5 in fp32; one storage quantum in the narrower formats, compared on the stored codes.
CompareRule ShadeRule(const Scene& scene) {
    const StorageFormat storage = scene.shade.storage;
    if (storage == StorageFormat::Fp32) return {CompareRule::Kind::Absolute, 1e-5};
    CompareRule rule{CompareRule::Kind::Codes, 1};
    rule.storage = storage;
    return rule;
}

CompareRule ShadowRule(const Scene&) { return {CompareRule::Kind::Absolute, 1e-5}; }

// SPEC 8: per channel 2/255 on 99.9 % of pixels, 8/255 everywhere.
CompareRule SplatImageRule(const Scene&) { return {CompareRule::Kind::Image, 2.0 / 255.0, 0.001, 8.0 / 255.0}; }

// SPEC 10: 1e-4 per linear channel on 99.9 % of pixels.
CompareRule MarchImageRule(const Scene&) {
    return {CompareRule::Kind::Image, 1e-4, 0.001, std::numeric_limits<double>::infinity()};
}

// SPEC 10a.
CompareRule NoiseRule(const Scene&) { return {CompareRule::Kind::Absolute, 1e-5}; }

// Noise reads nothing: static noise is made once, drifting noise every step (SPEC 14).
bool NoiseAnimated(const Scene& scene) { return scene.noise.Animated(); }

// Shares of time-slicing (core/pipeline/Backend.h SliceRange): slices k; rows of
// tiles; the sweep's slices, whose axis follows the sun at the step.
uint32_t SlicesOfK(const Scene& scene, uint32_t) { return scene.grid.size.nz; }
uint32_t RowsOfTiles(const Scene& scene, uint32_t) { return CeilDiv(scene.grid.size.ny, scene.density.tile); }
uint32_t SweepSlices(const Scene& scene, uint32_t step) {
    ShadeParams p;  // the plan's slices depend on the sun and the resolution alone
    p.sun = scene.sun.DirectionAt(step);
    p.resolution = scene.shade.resolution;
    return MakeShadePlan(p, scene.grid.size).nw;
}

// The splat renderer interpolates q between the last two steps, and skips
// boxes empty in both steps' occupancy.
std::vector<Resource> SplatPrevious(const Scene& scene) {
    if (scene.splat.skipping) return {Resource::Q, Resource::Tiles, Resource::Bands};
    return {Resource::Q};
}

// The ray marcher interpolates q between the last two steps, like the splat renderer.
std::vector<Resource> MarchPrevious(const Scene&) { return {Resource::Q}; }

// The table, made on first use: commands describe stages in their help text
// during static initialisation, before a namespace-scope table would exist.
// Fields left out take their defaults (GCC warns about designated initialisers that omit fields).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const std::array<StageDescriptor, kStageCount>& Descriptors() {
    static const std::array<StageDescriptor, kStageCount> table = {{
        {.stage = Stage::Region,
         .section = "ellipsoids",
         .writes = {Resource::Region},
         .shareCount = SlicesOfK,
         .symbol = "R",
         .rule = RegionRule},
        {.stage = Stage::Ca,
         .section = "ca",
         .reads = {Resource::Region, Resource::Hum, Resource::Act, Resource::Cld},
         .writes = {Resource::Hum, Resource::Act, Resource::Cld},
         .advancesState = true,
         .shareCount = SlicesOfK,
         .symbol = "cld",
         .rule = BitExact},
        {.stage = Stage::Smooth,
         .section = "smooth",
         .reads = {Resource::Cld},
         .writes = {Resource::Q},
         .shareCount = SlicesOfK,
         .symbol = "q",
         .rule = BitExact},
        {.stage = Stage::Density,
         .section = "density",
         .reads = {Resource::Q},
         .optionalReads = {Resource::Cld},
         .writes = {Resource::ColumnSum, Resource::Tiles, Resource::Bands},
         .skipsUnchangedInputs = true,
         .shareCount = RowsOfTiles,
         .symbol = "D",
         .rule = BitExact},
        {.stage = Stage::Shade,
         .section = "shade",
         .reads = {Resource::Q},
         .writes = {Resource::T},
         .outputStepsOnly = true,
         .skipsUnchangedInputs = true,
         .readsSun = true,
         .shareCount = SweepSlices,
         .symbol = "T",
         .rule = ShadeRule,
         .ruleNote = "one storage quantum with fp16 or unorm8 storage"},
        {.stage = Stage::Shadow,
         .section = "shadow",
         .reads = {Resource::ColumnSum},
         .writes = {Resource::Shadow},
         .outputStepsOnly = true,
         .skipsUnchangedInputs = true,
         .readsSun = true,
         .symbol = "G",
         .rule = ShadowRule},
        {.stage = Stage::RenderSplat,
         .section = "render",
         .reads = {Resource::Q, Resource::T, Resource::Tiles, Resource::Bands},
         .optionalReads = {Resource::Shadow},  // render.ground needs it: checked by the scene reader
         .readsPrevious = SplatPrevious,
         .writes = {Resource::SplatImage},
         .outputStepsOnly = true,
         .renderer = true,
         .symbol = "image",
         .rule = SplatImageRule},
        {.stage = Stage::RenderMarch,
         .section = "render",
         .reads = {Resource::Q},
         .optionalReads = {Resource::T, Resource::Shadow},  // march.light "shade" (the default) needs T,
                                                            // render.ground G: checked by the scene reader
         .readsPrevious = MarchPrevious,
         .writes = {Resource::MarchImage},
         .outputStepsOnly = true,
         .renderer = true,
         .symbol = "image",
         .rule = MarchImageRule},
        {.stage = Stage::Noise,
         .section = "noise",
         .writes = {Resource::Q},
         .skipsUnchangedInputs = true,
         .dependsOnStep = NoiseAnimated,
         .symbol = "q",
         .rule = NoiseRule},
    }};
    return table;
}
#pragma GCC diagnostic pop

bool Contains(const std::vector<Resource>& list, Resource r) {
    for (Resource x : list)
        if (x == r) return true;
    return false;
}

}  // namespace

const StageDescriptor& Describe(Stage stage) {
    const StageDescriptor& d = Descriptors()[size_t(stage)];
    assert(d.stage == stage && "the descriptors are in CB_STAGES order");
    return d;
}

std::optional<Stage> ProducerOf(Resource resource, const StageSet& enabled) {
    for (Stage s : kAllStages)
        if (enabled.Has(s) && Contains(Describe(s).writes, resource)) return s;
    return std::nullopt;
}

std::vector<Stage> ScheduleStages(const StageSet& enabled) {
    // Stage a must run before b when b reads what a writes (a does not advance
    // the state), or when a reads what b writes and b advances the state.
    auto before = [&](Stage a, Stage b) {
        const StageDescriptor &da = Describe(a), &db = Describe(b);
        for (const std::vector<Resource>* reads : {&db.reads, &db.optionalReads})
            for (Resource r : *reads)
                if (!da.advancesState && Contains(da.writes, r)) return true;
        for (const std::vector<Resource>* reads : {&da.reads, &da.optionalReads})
            for (Resource r : *reads)
                if (db.advancesState && Contains(db.writes, r)) return true;
        return false;
    };
    // Kahn's algorithm, taking ready stages in CB_STAGES order so the schedule
    // is stable, and stages that advance the state only when nothing else is
    // ready: they end the step, after the observer has seen step t whole.
    std::vector<Stage> pending, order;
    for (Stage s : kAllStages)
        if (enabled.Has(s)) pending.push_back(s);
    while (!pending.empty()) {
        auto ready = pending.end();
        for (bool advancing : {false, true}) {
            for (auto it = pending.begin(); it != pending.end() && ready == pending.end(); ++it) {
                if (Describe(*it).advancesState != advancing) continue;
                bool blocked = false;
                for (Stage other : pending)
                    if (other != *it && before(other, *it)) blocked = true;
                if (!blocked) ready = it;
            }
        }
        assert(ready != pending.end() && "the stage graph has no cycle");
        if (ready == pending.end()) ready = pending.begin();
        order.push_back(*ready);
        pending.erase(ready);
    }
    return order;
}

std::vector<MissingInput> MissingInputs(const StageSet& enabled) {
    std::vector<MissingInput> missing;
    for (Stage s : kAllStages) {
        if (!enabled.Has(s)) continue;
        for (Resource r : Describe(s).reads) {
            if (ProducerOf(r, enabled)) continue;
            MissingInput m{s, r, {}};
            for (Stage p : kAllStages)
                if (Contains(Describe(p).writes, r)) m.producers.push_back(p);
            missing.push_back(std::move(m));
        }
    }
    return missing;
}

ResourcePlan PlanResources(const Scene& scene) {
    ResourcePlan plan;
    for (Stage s : kAllStages) {
        if (!scene.stages.Has(s)) continue;
        const StageDescriptor& d = Describe(s);
        for (Resource r : d.writes) {
            plan.used[size_t(r)] = true;
            if (d.advancesState) plan.doubleBuffered[size_t(r)] = true;
        }
    }
    for (Stage s : kAllStages) {
        const StageDescriptor& d = Describe(s);
        if (!scene.stages.Has(s) || !d.readsPrevious) continue;
        for (Resource r : d.readsPrevious(scene))
            if (plan.used[size_t(r)]) plan.previous[size_t(r)] = true;
    }
    // Time-slicing's third buffer set (Fizimayer's thesis, section 7.1): the next step's
    // value of everything but the images and the double-buffered state.
    if (scene.render.slicesPerFrame > 0)
        for (Resource r : kAllResources)
            plan.pending[size_t(r)] = plan.used[size_t(r)] && !plan.doubleBuffered[size_t(r)] && !IsPerCamera(r);
    return plan;
}

std::string_view BufferRoleName(BufferRole role) {
    switch (role) {
        case BufferRole::Current:
            return "current";
        case BufferRole::Next:
            return "next";
        case BufferRole::Previous:
            return "previous";
        case BufferRole::Pending:
            return "pending";
    }
    return "?";
}

std::vector<PlannedBuffer> PlanBuffers(const Scene& scene) {
    const ResourcePlan plan = PlanResources(scene);
    std::vector<PlannedBuffer> buffers;
    for (Resource r : kAllResources) {
        const size_t i = size_t(r);
        if (!plan.used[i]) continue;
        const BufferFormat format = ResourceFormat(r);
        const Extent3 extent = ResourceExtent(r, scene);
        const size_t copies = IsPerCamera(r) ? scene.render.cameras.size() : 1;
        for (size_t n = 0; n < copies; ++n) buffers.push_back({r, BufferRole::Current, uint32_t(n), format, extent});
        if (plan.doubleBuffered[i]) buffers.push_back({r, BufferRole::Next, 0, format, extent});
        if (plan.previous[i]) buffers.push_back({r, BufferRole::Previous, 0, format, extent});
        if (plan.pending[i]) buffers.push_back({r, BufferRole::Pending, 0, format, extent});
    }
    return buffers;
}

}  // namespace cb
