// Grid sizes and voxel indexing (SPEC 0, docs/contract.md).
#pragma once

#include <cstddef>
#include <cstdint>

namespace cb {

struct Extent3 {
    uint32_t nx = 0, ny = 0, nz = 0;

    constexpr uint64_t Count() const { return uint64_t(nx) * ny * nz; }
    constexpr bool operator==(const Extent3&) const = default;
};

// Linear index v = i + nx*(j + ny*k), uint32 by contract (scenes whose voxel
// count does not fit are refused at load time).
constexpr uint32_t VoxelIndex(const Extent3& e, uint32_t i, uint32_t j, uint32_t k) {
    return i + e.nx * (j + e.ny * k);
}

// ceil(a / b) for b > 0, without the wrap of (a + b - 1) / b when a + b - 1 passes 2^32.
constexpr uint32_t CeilDiv(uint32_t a, uint32_t b) { return a / b + (a % b != 0 ? 1u : 0u); }

// A share of one stage call's work, for time-slicing (SPEC 13): the call
// computes only the slices [begin, end) of the stage's share axis, clamped to
// its share count, and leaves the rest of its outputs as they were. Running
// a step's shares in ascending order, each once, with nothing in between
// that writes the stage's outputs, gives exactly the whole call's outputs.
// The axis of each stage (docs/pipeline.md, "Time-slicing"):
//   region, ca, smooth   slices k; share count nz
//   density              rows of tiles; share count ceil(ny / tile). D, tiles
//                        and bands of those rows; coveredColumns counts the
//                        covered columns of those rows only (the shares' counts add up)
//   shade                the sweep's slices m (ShadePlan::SliceW, nearest the sun
//                        first); share count ShadePlan::nw. At resolution f > 1 the
//                        share holding m = 0 also fills the coarse grid and the share
//                        ending at nw writes T (until then T is left as it was). At
//                        f = 1 a share's slices of T may also wait for that share (a
//                        backend may carry the sweep in scratch); no other slice changes
// The default is the whole call.
struct SliceRange {
    uint32_t begin = 0;
    uint32_t end = UINT32_MAX;

    uint32_t Begin(uint32_t count) const { return begin < count ? begin : count; }
    uint32_t End(uint32_t count) const { return end < count ? end : count; }
    bool IsWhole(uint32_t count) const { return begin == 0 && end >= count; }
    bool operator==(const SliceRange&) const = default;
};

}  // namespace cb
