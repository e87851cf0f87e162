// The layered renderer's state on cpu (RenderLayersCpu.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"

namespace cb {
class Buffer;
}

namespace cb::cpu {

struct RenderLayersCpuState {
    static constexpr Stage kStage = Stage::RenderLayers;
    std::vector<std::array<float, 2>> volume;  // the padded (q_alpha, T) volume, wrapped horizontally with tiling
    std::vector<std::array<float, 3>> volumeWithSky;  // instead, with the sky light: (q_alpha, T, T_sky)
    std::vector<uint64_t> emptyTaps;                  // a bit per padded cell: its taps all read q = 0
    // What the volume and the bits were formed from: kept while a call's inputs match (LayersInputs::stamp).
    struct Formed {
        uint64_t stamp = 0;  // 0: nothing kept
        const Buffer *qPrev = nullptr, *qCur = nullptr, *T = nullptr, *TSky = nullptr;
        uint32_t alphaBits = 0;
        bool tiling = false;
        bool operator==(const Formed&) const = default;
    } formed;
    // The padded volume of pairs, or of triples with the sky light, and its bits of empty taps.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::cpu
