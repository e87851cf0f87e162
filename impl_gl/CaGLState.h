// The automaton's state on gl (CaGL.cpp).
#pragma once

#include <array>
#include <cstdint>

#include "core/scene/Scene.h"
#include "impl_gl/ScratchGL.h"

namespace cb::gl {

struct CaGLState {
    static constexpr Stage kStage = Stage::Ca;
    // Whether steps run in the thesis's layout (one RGBA8UI texel per voxel);
    // set by the façade when made.
    bool rgba8 = false;
    // With wind: the rules' humidity, activation and clouds, before advection.
    TextureSlot rulesHum, rulesAct, rulesCld;
    // RGBA8 layout: the state between steps (see stateOf) and the rules' output.
    TextureSlot stateA, stateB;
    // Which packed fields the thesis-layout state in stateA holds: the last
    // step's outputs, valid while the façade's count of bit-field writes is
    // stateWrites.
    std::array<GLuint, 3> stateOf{};
    uint64_t stateWrites = ~uint64_t(0);
    // Steps in shares, RGBA8 layout: stateA holds `inputs` for slices
    // [packedBegin, packedEnd) and stateB this step's rule results for
    // [0, rulesEnd), valid while no bit field is written but by the shares.
    struct ShareState {
        std::array<GLuint, 3> inputs{}, outputs{};
        Extent3 extent;
        uint64_t bitsWrites = ~uint64_t(0);
        bool wind = false;
        uint32_t packedBegin = 0, packedEnd = 0, rulesEnd = 0;
    };
    ShareState share;
    // With wind, the three rule outputs as bit fields; in the RGBA8 layout, the two states.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::gl
