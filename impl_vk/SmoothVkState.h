// Smooth's state on vk (SmoothVk.cpp).
#pragma once

#include <cstdint>
#include <optional>

#include "core/pipeline/Backend.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct SmoothVkState {
    static constexpr Stage kStage = Stage::Smooth;
    BufferSlot sumX;   // the bit field summed along x
    BufferSlot sumXY;  // those sums summed along y; kept between the shares of a sweep
    // The share sequence whose x-y sums are in sumXY: the slices [0, summedTo)
    // of `cld` at `radius`, its next share starting at `next`. Reset by every
    // smooth call that does not continue it.
    struct Sweep {
        const Buffer* cld = nullptr;
        int radius = 0;
        uint32_t next = 0, summedTo = 0;
    };
    std::optional<Sweep> sweep;
    // The two sum volumes, a uint per voxel each.
    uint64_t ScratchBytes(const Scene& scene) const { return 2 * scene.grid.size.Count() * 4; }
};

}  // namespace cb::vk
