// One stage's call on a backend, from the buffers of its resources: what the
// simulation runs every step, and what `conform` runs on another backend with
// the CPU's inputs. Each stage's call (its parameters, its entry point, its
// host-side work) is written here once.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/pipeline/StageDescriptors.h"
#include "core/scene/Scene.h"

namespace cb {

// The buffers of one call, by resource (core/pipeline/StageDescriptors.h): inputs are
// `current` (and `previous` for an interpolating renderer); outputs go to
// `current`, or to `next` for a stage that advances the state. Images hold
// one buffer per camera.
struct StageBuffers {
    std::array<std::vector<Buffer*>, kResourceCount> current;
    std::array<Buffer*, kResourceCount> previous{};
    std::array<Buffer*, kResourceCount> next{};

    Buffer* Current(Resource r, size_t n = 0) const {
        const auto& list = current[size_t(r)];
        return n < list.size() ? list[n] : nullptr;
    }
    Buffer* Previous(Resource r) const { return previous[size_t(r)]; }
    Buffer* Next(Resource r) const { return next[size_t(r)]; }
};

// What a stage reads from the host rather than from a resource.
struct StageHostInputs {
    uint32_t step = 0;
    std::span<const RasterEllipsoid> raster;  // region: step t's ellipsoids
    // Renderers: the frame of the step (0 .. frames - 1) and the step's frames (0: render.frames_per_step), which
    // set alpha (RenderSettings::FrameAlpha).
    uint32_t frame = 0;
    uint32_t frames = 0;
    // Region, ca, smooth, density and shade: the share of the stage to compute (time-slicing; core/pipeline/Backend.h).
    SliceRange slices;
    // Pipelined timing: call backend.MarkBatch() before each backend call (StageCallRecord::marks).
    bool markBatch = false;
};

// One rendered image.
struct FrameRecord {
    Stage renderer = Stage::RenderSplat;
    std::string camera;
    uint32_t frame = 0;  // the frame of its step (render.frames_per_step)
    float alpha = 0;     // the interpolation weight it was drawn with
    // Wall time of its call, ms; pipelined (markBatch), the host's recording time.
    double ms = 0;
    bool pipelined = false;          // drawn in a batch (pipelined timing)
    std::optional<double> deviceMs;  // its device time, where the backend measures it
    SplatStats stats;
    MarchStats march;  // render_march's counters
};

// What one call measured and returned besides its buffers.
struct StageCallRecord {
    double ms = 0;                           // wall time of the backend's calls
    std::optional<double> deviceMs;          // where the backend measures it (not with markBatch)
    std::optional<uint32_t> coveredColumns;  // density
    std::vector<FrameRecord> frames;         // renderers, one per camera
    // With markBatch: one entry per MarkBatch() the call made, in order: the
    // index in `frames` of the frame it drew, or nullopt for a stage's own call.
    std::vector<std::optional<size_t>> marks;
};

// Runs `stage` on `backend`. The buffers must hold every resource the stage's
// descriptor reads and writes in this scene; an error names the stage.
// Marks the stage and step for crash reports (MarkPhase) and honours the
// test-only fault switch (InjectTestFault) before the call.
Status CallStage(Stage stage, Backend& backend, const Scene& scene, const StageHostInputs& host,
                 const StageBuffers& buffers, StageCallRecord& record);

}  // namespace cb
