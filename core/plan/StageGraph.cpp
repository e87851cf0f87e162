#include "core/plan/StageGraph.h"

#include <algorithm>
#include <cassert>
#include <iterator>
#include <set>

#include "core/pipeline/LightTerms.h"

namespace cb {

// Each stage's module names its descriptor Describe<Stage> and its adapter
// Call<Stage> (its header declares them alike); the declarations and tables here
// expand CB_STAGES, so a stage without them does not link.
#define CB_STAGE_DECLARE(name, text, spec, splat)                                                                \
    const StageDescriptor& Describe##name();                                                                     \
    Status Call##name(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io, \
                      StageCallRecord& record);
CB_STAGES(CB_STAGE_DECLARE)
#undef CB_STAGE_DECLARE

namespace {

// Describe<Stage> returns a function-local static, made on first use: commands
// describe stages in their help text during static initialisation. The fields
// it leaves out take their defaults (each module silences GCC's warning about that).
using DescribeFn = const StageDescriptor& (*)();
constexpr DescribeFn kDescriptors[] = {
#define CB_STAGE_DESCRIBE(name, text, spec, splat) &Describe##name,
    CB_STAGES(CB_STAGE_DESCRIBE)
#undef CB_STAGE_DESCRIBE
};
constexpr StageAdapter kAdapters[] = {
#define CB_STAGE_ADAPTER(name, text, spec, splat) &Call##name,
    CB_STAGES(CB_STAGE_ADAPTER)
#undef CB_STAGE_ADAPTER
};
static_assert(std::size(kDescriptors) == kStageCount && std::size(kAdapters) == kStageCount);

bool Contains(const std::vector<Resource>& list, Resource r) {
    for (Resource x : list)
        if (x == r) return true;
    return false;
}

}  // namespace

const StageDescriptor& Describe(Stage stage) {
    const StageDescriptor& d = kDescriptors[size_t(stage)]();
    assert(d.stage == stage && "each module describes its own stage");
    return d;
}

const std::vector<Stage>& RendererStages() {
    static const std::vector<Stage> renderers = [] {
        std::vector<Stage> out;
        for (Stage s : kAllStages)
            if (Describe(s).renderer) out.push_back(s);
        return out;
    }();
    return renderers;
}

std::string RendererNames(std::string_view last) {
    const std::vector<Stage>& renderers = RendererStages();
    std::string names;
    for (size_t i = 0; i < renderers.size(); ++i)
        names += std::string(i == 0                      ? ""
                             : i + 1 == renderers.size() ? last
                                                         : ", ") +
                 std::string(StageName(renderers[i]));
    return names;
}

bool RunsARenderer(const StageSet& enabled) {
    return std::ranges::any_of(kAllStages, [&](Stage s) { return Describe(s).renderer && enabled.Has(s); });
}

StageAdapter AdapterOf(Stage stage) { return kAdapters[size_t(stage)]; }

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

bool FieldsListed(std::span<const std::string_view> fields, std::string_view path) {
    return std::ranges::any_of(fields, [&](std::string_view f) { return FieldsOverlap(path, f); });
}

namespace {

// Depth-first over the writers of the stage's inputs; `seen` stops at a stage that reads its own outputs.
bool FieldsReach(Stage stage, std::string_view path, std::set<Stage>& seen) {
    if (!seen.insert(stage).second) return false;
    const StageDescriptor& d = Describe(stage);
    if (FieldsListed(d.sceneFields, path)) return true;
    // Every renderer takes the light terms (MakeLightTerms).
    if (d.renderer && FieldsListed(kLightTermFields, path)) return true;
    // Scene::needs follows from the renderers' relightFields (shade's sun is fixed at step 0's when one relights).
    if (d.readsRendererNeeds && std::ranges::any_of(RendererStages(), [&](Stage s) {
            return FieldsListed(Describe(s).renderer->relightFields, path);
        }))
        return true;
    std::vector<Resource> inputs = d.reads;
    inputs.insert(inputs.end(), d.optionalReads.begin(), d.optionalReads.end());
    for (Stage writer : kAllStages) {
        const std::vector<Resource>& writes = Describe(writer).writes;
        const bool feeds =
            std::ranges::any_of(inputs, [&](Resource r) { return std::ranges::find(writes, r) != writes.end(); });
        if (feeds && FieldsReach(writer, path, seen)) return true;
    }
    return false;
}

}  // namespace

bool StageOutputReads(Stage stage, std::string_view path) {
    if (FieldsListed(kFieldsEveryStageReads, path)) return true;
    std::set<Stage> seen;
    return FieldsReach(stage, path, seen);
}

}  // namespace cb
