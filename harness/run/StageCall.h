// One stage's call on a backend through its module's adapter (core/pipeline/StageAdapter.h):
// what the simulation runs every step, and what `conform` runs on another
// backend with the CPU's inputs.
#pragma once

#include "core/pipeline/Backend.h"
#include "core/pipeline/StageAdapter.h"
#include "core/scene/Scene.h"

namespace cb {

// Runs `stage` on `backend`. The buffers must hold every resource the stage's
// descriptor reads and writes in this scene; an error names the stage.
// Marks the stage and step for crash reports (MarkPhase) and honours the
// test-only fault switch (InjectTestFault) before the call.
Status CallStage(Stage stage, Backend& backend, const Scene& scene, const StageHostInputs& host,
                 const StageBuffers& buffers, StageCallRecord& record);

}  // namespace cb
