// The memory a scene needs, priced from the buffer plan (PlanBuffers,
// core/pipeline/StageDescriptors.h), the list the simulation allocates, so that the
// estimate cannot drift from the allocation. The loader's check prices the
// plan in the host layout (EstimateSceneBytes, core/scene/Scene.h); at run time each
// backend prices it in its own (Backend::BufferBytes, Backend::ScratchBytes).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "core/base/ProcessMemory.h"
#include "core/pipeline/Backend.h"

namespace cb {

struct Scene;

// Spare zero bytes after a host U8 buffer, so that kernels may read a full
// 64-voxel word past a row's end.
inline constexpr uint64_t kHostU8Padding = 64;

// Bytes of one buffer in the host layout, the CPU backend's: bit fields as
// rows of ceil(nx/64) 64-bit words, U8 one byte per voxel plus
// kHostU8Padding, F32 four bytes per voxel. Saturates at UINT64_MAX.
uint64_t HostBufferBytes(BufferFormat format, const Extent3& extent);

// The host buffer read-backs go through (dumps, the renderer's first previous
// step), one at a time: the largest planned buffer in canonical bytes.
uint64_t HostStagingBytes(const Scene& scene);

// Bytes the scene's planned buffers take in the host layout, plus the host
// staging buffer (the loader's memory check; core/pipeline/MemoryPlan.h).
uint64_t EstimateSceneBytes(const Scene& scene);

// Every planned buffer priced by `backend`, plus its scratch for the scene.
// Saturates at UINT64_MAX.
uint64_t PlannedBytes(const Scene& scene, const Backend& backend);

// Fails, naming the backend, the bytes needed and the bytes available, when
// the backend reports its available memory and PlannedBytes exceeds it.
Status CheckPlannedBytesFit(const Scene& scene, const Backend& backend);

}  // namespace cb
