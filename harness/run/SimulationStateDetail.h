// Internal to harness/run/SimulationState.cpp and harness/run/SimulationStateRead.cpp:
// the helpers both the writer and the reader of a saved state use (the data
// hash, the file names and the shapes of the manifest).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/math/Grid.h"
#include "core/pipeline/Backend.h"
#include "core/plan/StageGraph.h"

namespace cb::simulation_state_detail {

inline uint64_t Fnv1a64(std::span<const std::byte> bytes) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (std::byte b : bytes) {
        h ^= uint64_t(b);
        h *= 0x100000001b3ull;
    }
    return h;
}

inline std::string Hex64(uint64_t v) {
    char text[19];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
    return text;
}

inline std::string_view FormatName(BufferFormat format) {
    switch (format) {
        case BufferFormat::Bits:
            return "bits";
        case BufferFormat::U8:
            return "u8";
        case BufferFormat::F32:
            return "f32";
    }
    return "?";
}

// "q.current.npy", "image_splat.current.0.npy".
inline std::string FileOf(Resource resource, BufferRole role, uint32_t camera) {
    std::string name = std::string(ResourceName(resource)) + "." + std::string(BufferRoleName(role));
    if (IsPerCamera(resource)) name += "." + std::to_string(camera);
    return name + ".npy";
}

inline std::vector<uint64_t> ShapeOf(const Extent3& e) { return {e.nz, e.ny, e.nx}; }

}  // namespace cb::simulation_state_detail
