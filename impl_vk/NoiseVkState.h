// The noise former's state on vk (NoiseVk.cpp).
#pragma once

#include <cstdint>
#include <memory>

#include "core/math/Noise.h"
#include "core/scene/Scene.h"
#include "impl_vk/ScratchVk.h"

namespace cb::vk {

struct NoiseVkState {
    static constexpr Stage kStage = Stage::Noise;
    // The scene whose data block (core/math/NoiseGpu.h) is in `data`, kept while it stays.
    std::unique_ptr<noise::NoiseForm> form;
    BufferSlot data;
    // The data block: header, two tables, HD per slice, towers, detail volume.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::vk
