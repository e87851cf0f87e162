// What the memory check of a scene compares: the estimate of what a scene
// allocates (EstimateSceneBytes, core/Scene.h) against the machine's memory.
// Internal to core.
#pragma once

#include <cstdint>
#include <optional>

namespace cb::scene_io {

// Physical memory in bytes, or nullopt when the system does not say.
std::optional<uint64_t> PhysicalMemoryBytes();

}  // namespace cb::scene_io
