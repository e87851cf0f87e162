// Smooth's state on cpu (SmoothCpu.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/scene/Scene.h"
#include "impl_cpu/BitField.h"

namespace cb::cpu {

// What smooth keeps between the shares of one sweep: the ring of slices
// filtered in x and y, valid for a share that starts at `next` on the same cld
// field and radius.
struct SmoothShareState {
    const BitField* cld = nullptr;  // not owned; nullptr: nothing to resume
    int radius = 0;
    Extent3 extent;
    uint32_t next = 0;          // the first output slice of the share that may resume
    uint32_t filtered = 0;      // slices below this one have been filtered into the ring
    std::vector<uint8_t> ring;  // 2 radius + 1 slices of numerators (1 or 2 bytes each)
    std::vector<uint8_t> xs;    // one slice of x sums
};

struct SmoothCpuState {
    static constexpr Stage kStage = Stage::Smooth;
    int threads = 1;         // the façade's arena's, set when it is made
    SmoothShareState share;  // smooth in shares (time-slicing)
    // At radius r > 0, each run of slices (one per thread, at most nz) keeps a
    // ring of 2r + 1 slices of numerators, a slice of x sums and two rows; in
    // shares, `share` keeps a ring and a slice of x sums between calls.
    uint64_t ScratchBytes(const Scene& scene) const;
};

}  // namespace cb::cpu
