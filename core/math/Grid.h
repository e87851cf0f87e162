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

}  // namespace cb
