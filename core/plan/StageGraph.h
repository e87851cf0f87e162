// The stage graph: every stage's descriptor (from its module, core/stages/<stage>/),
// the order a step runs the enabled stages in, and the buffers a scene's stages
// use. The simulation, `conform`, `dump`, the memory plan and the conformance
// tests walk these instead of naming stages.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/Scene.h"
#include "core/scene/Stage.h"

namespace cb {

// The stage's descriptor, from its module.
const StageDescriptor& Describe(Stage stage);
// Whether any of `enabled` is a renderer (its descriptor's `renderer`).
bool RunsARenderer(const StageSet& enabled);
// Whether `path` (a dotted scene field) overlaps one of `fields` (FieldsOverlap).
bool FieldsListed(std::span<const std::string_view> fields, std::string_view path);
// Whether `path` can change what `stage` writes: it overlaps a field of kFieldsEveryStageReads or of the
// stage's sceneFields, or one that a stage writing a resource it reads (reads and optionalReads) depends on,
// transitively; a renderer's also follows the light terms' sections (kLightTermFields), and shade's the fields
// that make a renderer relight (Scene::needs).
bool StageOutputReads(Stage stage, std::string_view path);
// The renderers (stages with a RendererDescriptor), in stage order.
const std::vector<Stage>& RendererStages();
// Their names for a message or a help text, joined by ", " and by `last` before the last one
// ("render_splat, render_march or render_layers").
std::string RendererNames(std::string_view last);
// The stage's call adapter, from its module (core/pipeline/StageAdapter.h).
StageAdapter AdapterOf(Stage stage);

// The enabled stages in the order a step runs them: every producer before
// the stages that read its outputs, and stages that advance the state after
// every other stage (they end the step).
std::vector<Stage> ScheduleStages(const StageSet& enabled);

// The stage among `enabled` that writes `resource`, if any.
std::optional<Stage> ProducerOf(Resource resource, const StageSet& enabled);

// An enabled stage's input that no enabled stage writes, and the stages that could.
struct MissingInput {
    Stage stage;
    Resource resource;
    std::vector<Stage> producers;
};
std::vector<MissingInput> MissingInputs(const StageSet& enabled);

// The resources a scene's enabled stages write, and which of them are also
// kept for the previous step (read by an interpolating renderer).
struct ResourcePlan {
    std::array<bool, kResourceCount> used{};
    std::array<bool, kResourceCount> previous{};
    std::array<bool, kResourceCount> doubleBuffered{};  // written by a stage that advances the state
    std::array<bool, kResourceCount> pending{};         // time-slicing: the next step's value, computed over frames
};
ResourcePlan PlanResources(const Scene& scene);

// Which copy of a resource a buffer holds: this step's, the next step's (a
// state-advancing writer's output), the previous step's (an interpolating
// renderer's input), or the next step's value being computed over the frames
// of this one (time-slicing's third set, render.slices_per_frame > 0).
enum class BufferRole : uint8_t { Current, Next, Previous, Pending };
std::string_view BufferRoleName(BufferRole role);  // "current", "next", "previous", "pending"

struct PlannedBuffer {
    Resource resource;
    BufferRole role = BufferRole::Current;
    uint32_t camera = 0;  // per-camera resources: the camera's index; 0 otherwise
    BufferFormat format = BufferFormat::F32;
    Extent3 extent;
    bool operator==(const PlannedBuffer&) const = default;
};

// Every buffer a simulation of `scene` allocates, in allocation order: per
// resource its current buffers (one per camera for images), then its next, then its
// previous, then its pending. Simulation::Allocate allocates exactly these; the memory plan prices them.
std::vector<PlannedBuffer> PlanBuffers(const Scene& scene);

}  // namespace cb
