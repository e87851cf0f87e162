// The Vulkan region's per-tile ellipsoid lists (impl_vk/RegionTileLists.h):
// hand-worked lists, and the linear-time builder against the plain scan of
// every tile against every ellipsoid that it replaced.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#if CLOUDBENCH_HAVE_VK
#include "impl_vk/RegionTileLists.h"

namespace cb::vk {
namespace {

// The slow path: every tile of slices [k0, k1) tested against every ellipsoid, in index order.
RegionTileLists ScanEveryTile(const std::vector<RasterEllipsoid>& ellipsoids, const Extent3& e, uint32_t k0,
                              uint32_t k1) {
    RegionTileLists lists;
    lists.tilesX = (e.nx + 15) / 16;
    lists.tilesY = (e.ny + 15) / 16;
    lists.starts.push_back(0);
    for (uint32_t k = k0; k < k1; ++k)
        for (uint32_t ty = 0; ty < lists.tilesY; ++ty)
            for (uint32_t tx = 0; tx < lists.tilesX; ++tx) {
                for (uint32_t n = 0; n < ellipsoids.size(); ++n)
                    if (EllipsoidReachesRegionTile(ellipsoids[n], e, tx, ty, k)) lists.entries.push_back(n);
                lists.starts.push_back(uint32_t(lists.entries.size()));
            }
    return lists;
}

// One ellipsoid of semi-axes (3, 3, 1) centred at (8, 8, 5): its box widened by two voxels reaches
// x, y in [3, 13] (tile 0 only, centres 0.5 .. 15.5) and z in [2, 8], so slices k = 2 .. 7 (centres
// 2.5 .. 7.5). A second, (1, 1, 1) at (16, 8, 5), reaches x in [13, 19]: the last centre of tile 0
// (15.5) and the first of tile 1 (16.5), and slices 2 .. 7 likewise (|k + 0.5 - 5| <= 3).
TEST(RegionTileLists, HandWorkedLists) {
    const Extent3 e{48, 32, 10};
    const std::vector<RasterEllipsoid> ellipsoids = {{{8, 8, 5}, {3, 3, 1}, 1, 0}, {{16, 8, 5}, {1, 1, 1}, 1, 0}};
    const RegionTileLists lists = BuildRegionTileLists(ellipsoids, e, 0, 10);
    ASSERT_EQ(lists.tilesX, 3u);
    ASSERT_EQ(lists.tilesY, 2u);
    ASSERT_EQ(lists.starts.size(), 3u * 2u * 10u + 1u);
    auto listOf = [&](uint32_t tx, uint32_t ty, uint32_t k) {
        const uint32_t tile = tx + 3 * (ty + 2 * k);
        return std::vector<uint32_t>(lists.entries.begin() + lists.starts[tile],
                                     lists.entries.begin() + lists.starts[tile + 1]);
    };
    for (uint32_t k = 0; k < 10; ++k) {
        const bool inside = k >= 2 && k <= 7;
        EXPECT_EQ(listOf(0, 0, k), inside ? std::vector<uint32_t>({0, 1}) : std::vector<uint32_t>()) << k;
        EXPECT_EQ(listOf(1, 0, k), inside ? std::vector<uint32_t>({1}) : std::vector<uint32_t>()) << k;
        EXPECT_TRUE(listOf(2, 0, k).empty()) << k;
        for (uint32_t tx = 0; tx < 3; ++tx) EXPECT_TRUE(listOf(tx, 1, k).empty()) << tx << " " << k;
    }
    EXPECT_EQ(lists.entries.size(), 6u * 3u);
    // A share of slices [4, 6) lists those slices only, numbered from slice 4.
    const RegionTileLists share = BuildRegionTileLists(ellipsoids, e, 4, 6);
    ASSERT_EQ(share.starts.size(), 3u * 2u * 2u + 1u);
    EXPECT_EQ(share.entries, (std::vector<uint32_t>{0, 1, 1, 0, 1, 1}));
}

// Random ellipsoids of every size, partly or wholly outside odd-sized grids, in whole calls and
// shares: exactly the lists of the plain scan, in the same order.
TEST(RegionTileLists, EqualToScanningEveryTile) {
    std::mt19937 rng(20261130);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const Extent3 grids[] = {{37, 29, 11}, {16, 16, 4}, {100, 7, 3}, {1, 1, 1}};
    for (const Extent3& e : grids) {
        std::vector<RasterEllipsoid> ellipsoids;
        for (int n = 0; n < 60; ++n) {
            const float scale = n % 3 == 0 ? 40.0f : n % 3 == 1 ? 4.0f : 0.3f;
            RasterEllipsoid el{{(unit(rng) * 1.6f - 0.3f) * float(e.nx), (unit(rng) * 1.6f - 0.3f) * float(e.ny),
                                (unit(rng) * 1.6f - 0.3f) * float(e.nz)},
                               {0.1f + unit(rng) * scale, 0.1f + unit(rng) * scale, 0.1f + unit(rng) * scale / 4},
                               1,
                               0};
            // Some centres exactly on tile edges and voxel centres, where the comparisons tie.
            if (n % 7 == 0) el.center[0] = float(16 * (n % 3)) + (n % 2 ? 0.5f : 0.0f);
            if (n % 5 == 0) el.center[2] = float(n % int(e.nz)) + 0.5f;
            ellipsoids.push_back(el);
        }
        const std::pair<uint32_t, uint32_t> ranges[] = {{0, e.nz}, {0, 1}, {e.nz / 2, e.nz}, {e.nz - 1, e.nz}};
        for (auto [k0, k1] : ranges) {
            const RegionTileLists fast = BuildRegionTileLists(ellipsoids, e, k0, k1);
            const RegionTileLists slow = ScanEveryTile(ellipsoids, e, k0, k1);
            EXPECT_EQ(fast.starts, slow.starts) << e.nx << "x" << e.ny << "x" << e.nz << " k " << k0 << "-" << k1;
            EXPECT_EQ(fast.entries, slow.entries) << e.nx << "x" << e.ny << "x" << e.nz << " k " << k0 << "-" << k1;
            EXPECT_FALSE(slow.entries.empty() && k1 - k0 > 1 && e.nx > 1);  // the case exercises lists
        }
    }
}

}  // namespace
}  // namespace cb::vk
#endif
