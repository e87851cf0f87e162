// The region stage's per-tile ellipsoid lists on Vulkan (RegionVk.cpp,
// region.comp): for each 16x16-voxel tile of each slice of a share, the
// ellipsoids whose bounding box, widened by two voxels, reaches a voxel centre
// of the tile. Built in time linear in the tiles plus the (tile, ellipsoid)
// pairs it lists, not tiles times ellipsoids.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/math/Grid.h"
#include "core/math/Rules.h"

namespace cb::vk {

inline constexpr uint32_t kRegionTile = 16;  // region.comp's tile edge, voxels

struct RegionTileLists {
    uint32_t tilesX = 0, tilesY = 0;
    // Tile (tx, ty) of slice k in [k0, k1) is tx + tilesX * (ty + tilesY * (k - k0)); its list is
    // entries[starts[tile] .. starts[tile + 1]), ellipsoid indices in ascending order.
    std::vector<uint32_t> starts, entries;
};

// Whether ellipsoid `el` belongs to the list of tile (tx, ty) of slice k: the
// shader's rejection test, widened by a voxel, meets a voxel centre of the tile.
bool EllipsoidReachesRegionTile(const RasterEllipsoid& el, const Extent3& grid, uint32_t tx, uint32_t ty, uint32_t k);

// The lists of slices [k0, k1) of `grid`: exactly the pairs EllipsoidReachesRegionTile accepts.
RegionTileLists BuildRegionTileLists(std::span<const RasterEllipsoid> ellipsoids, const Extent3& grid, uint32_t k0,
                                     uint32_t k1);

}  // namespace cb::vk
