// Stage `ca`'s types (SPEC 3, docs/contract.md): Dobashi's automaton's settings (section `ca`), its
// fields and its parameters.
// The scene (core/scene/Scene.h) and the backend interface (core/pipeline/Backend.h) include
// this header; the stage's reader, parameters, descriptor and call are beside it.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/math/Grid.h"

namespace cb {

class Buffer;  // core/pipeline/Backend.h

// Per-slice integer wind shift for Dobashi advection, in voxels per step.
struct SliceShift {
    int32_t sx = 0, sy = 0;
};

struct CaSettings {
    uint32_t seed = 1;
    double hum0 = 0.35;   // initial humidity probability
    double act0 = 0.001;  // initial activation probability
    double pExt = 0.1;
    double pHum = 0.1;
    double pAct = 0.001;
    // Empty: no advection. Otherwise exactly nz entries (a one-entry list in
    // the file is expanded to every slice).
    std::vector<SliceShift> windShift;

    bool HasWind() const {
        for (const SliceShift& s : windShift)
            if (s.sx != 0 || s.sy != 0) return true;
        return false;
    }
};

// The automaton's three bit fields at one step.
struct CaFields {
    Buffer* hum = nullptr;
    Buffer* act = nullptr;
    Buffer* cld = nullptr;
};
struct ConstCaFields {
    const Buffer* hum = nullptr;
    const Buffer* act = nullptr;
    const Buffer* cld = nullptr;
};

// Inputs of one automaton step t -> t+1 (SPEC 3). Probabilities are already
// quantised: q* = Q(p*).
struct CaStepParams {
    uint32_t seed = 0;
    uint32_t step = 0;
    uint32_t qExt = 0, qHum = 0, qAct = 0;
    // Empty, or one (sx, sy) per slice k.
    std::span<const int32_t> shiftX, shiftY;
    SliceRange slices;  // the slices k of `out` to write
};

struct CaInitParams {
    uint32_t seed = 0;
    uint32_t qHum0 = 0, qAct0 = 0;
};

}  // namespace cb
