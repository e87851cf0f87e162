// How the CPU's shade sweep is cut into tiles for threads (ShadeCpu.cpp), as
// numbers: the benchmark reports its work and span, the tests check it.
#pragma once

#include <cstdint>

namespace cb {
struct ShadePlan;
}

namespace cb::cpu {

// Bands along u are at least this many cells wide.
inline constexpr uint32_t kMinBandCells = 8;
// A tile aims at about this many cells (a few microseconds of one core).
inline constexpr double kTileCells = 16384;
// Sweeps along x (rows along y, strided): the fewest rows (z) for which they
// are tiled as below (fewer take the generic path), rows per band (a tile
// copies its halo row and column for every slice, so larger tiles copy less),
// the narrowest chunk of a row, and slices per tile (the floats of a 64-byte
// cache line).
inline constexpr uint32_t kMinStridedRows = 4;
inline constexpr uint32_t kStridedBandRows = 8;
inline constexpr uint32_t kMinChunkCells = 32;
inline constexpr uint32_t kLineFloats = 16;

// Tile (band i, chunk j, block M) covers band i of the slice plane (along u
// or v), chunk j of its rows (along u; sweeps along x only) and the block's
// slices; it runs once tiles (i, j, M - 1), (i + dir, j, M) and
// (i, j + chunkDir, M) are done.
struct ShadeSchedule {
    int axis = 0;                   // the banded axis: 0 = u, 1 = v
    uint32_t bands = 1;             // 1 (and one chunk): the sweep runs on the calling thread as one tile
    uint32_t chunks = 1;            // chunks of chunkCells along u (the last may be short); 1: whole rows
    uint32_t chunkCells = 0;        // a multiple of kLineFloats
    uint32_t blockSlices = 1;       // slices per tile
    uint32_t blocks = 1;
    bool towardHigher = true;       // dir = +1: band i reads band i + 1
    bool chunkTowardHigher = true;  // chunkDir = +1: chunk j reads chunk j + 1
    double work = 0, span = 0;      // cells in all, and on the longest chain of tiles
};

// The schedule for slices [m0, m1) of `plan` on `threads` threads.
ShadeSchedule MakeShadeSchedule(const ShadePlan& plan, int threads, uint32_t m0, uint32_t m1);

}  // namespace cb::cpu
