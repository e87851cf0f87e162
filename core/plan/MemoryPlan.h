// The memory a scene needs, priced from the buffer plan (PlanBuffers,
// core/plan/StageGraph.h), the list the simulation allocates, so that the
// estimate cannot drift from the allocation. The loader's check prices the
// plan in the host layout (EstimateSceneBytes, here); at run time each
// backend prices it in its own (Backend::BufferBytes, Backend::ScratchBytes).
// Beside it, whether the scene is within the backend's device limits.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "core/base/ProcessMemory.h"
#include "core/pipeline/Backend.h"

namespace cb {

struct Scene;

// The host buffer read-backs go through (dumps, the renderer's first previous
// step), one at a time: the largest planned buffer in canonical bytes.
uint64_t HostStagingBytes(const Scene& scene);

// Bytes the scene's planned buffers take in the host layout, plus the host
// staging buffer (the loader's memory check; core/plan/MemoryPlan.h).
uint64_t EstimateSceneBytes(const Scene& scene);

// Every planned buffer priced by `backend`, plus its scratch for the scene.
// Saturates at UINT64_MAX.
uint64_t PlannedBytes(const Scene& scene, const Backend& backend);

// Fails, naming the backend, the bytes needed and the bytes available, when
// the backend reports its available memory and PlannedBytes exceeds it.
Status CheckPlannedBytesFit(const Scene& scene, const Backend& backend);

// Fails with `file: field: reason` (the scene's file, the setting, the backend
// and the limit named) when a setting of `scene` is past one of the backend's
// device limits (Backend::ExceededLimit); checked before any stage runs.
Status CheckDeviceLimits(const Scene& scene, const Backend& backend);

}  // namespace cb
