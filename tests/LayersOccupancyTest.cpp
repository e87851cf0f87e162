// The CPU layers' empty-space skip (impl_cpu/LayersOccupancyCpu-inl.h): its bits worked by hand, and the fast path
// against the slow path it replaces: LayersPixel with the skipping fetch equals LayersPixel with a plain fetch, bit
// for bit, on every pixel of layers-small's cameras over sparse random clouds, tiled and not, with LOD0's
// billboards and with the sky light's third field.
#include <gtest/gtest.h>
#include <hwy/highway.h>  // the per-target helpers below, at this file's static target

#include <array>
#include <string>
#include <vector>

#include "core/math/Layers.h"
#include "core/plan/SceneLoad.h"
#include "core/stages/render_layers/RenderLayers.h"
#include "impl_cpu/LayersOccupancyCpu-inl.h"
#include "impl_cpu/PaddedVolumeCpu-inl.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

// Test the bits on a 3 x 2 x 2 grid (padded 5 x 4 x 4) holding one cloudy voxel, (1, 0, 0), at padded (2, 1, 1):
// the bases whose taps reach it are (1..2, 0..1, 0..1), eight of them; every other base that a tap can start from
// (i < 4, j < 3, k < 3) is empty, and the last column, row and slab are never set.
TEST(LayersOccupancy, EmptyTapsByHand) {
    const Extent3 e{3, 2, 2};
    std::vector<std::array<float, 2>> volume;
    cpu::HWY_NAMESPACE::FormPaddedVolume(volume, e, false, std::array<float, 2>{0.0f, 1.0f}, [](size_t v) {
        return std::array<float, 2>{v == 1 ? 0.5f : 0.0f, 1.0f};
    });
    std::vector<uint64_t> bits;
    cpu::HWY_NAMESPACE::FormEmptyTaps(bits, volume, e, [](const std::array<float, 2>& c) { return c[0]; });
    const cpu::HWY_NAMESPACE::LayersPaddedFetch<std::array<float, 2>> fetch{volume.data(), bits.data()};
    int set = 0;
    for (uint32_t k = 0; k < 4; ++k)
        for (uint32_t j = 0; j < 4; ++j)
            for (uint32_t i = 0; i < 5; ++i) {
                const bool base = i < 4 && j < 3 && k < 3;
                const bool reaches = i >= 1 && i <= 2 && j <= 1 && k <= 1;
                EXPECT_EQ(fetch.TapsEmpty(i + 5 * (j + 4 * k)), base && !reaches) << i << " " << j << " " << k;
                set += fetch.TapsEmpty(i + 5 * (j + 4 * k)) ? 1 : 0;
            }
    EXPECT_EQ(set, 4 * 3 * 3 - 8);
}

// A plain fetch over the same cells: LayersSampleAt blends every fragment.
template <class Cell>
struct PlainFetch {
    const Cell* volume;
    Cell operator()(uint32_t i) const { return volume[i]; }
};

// The skipping fetch, counting its skips.
template <class Cell>
struct CountingFetch : cpu::HWY_NAMESPACE::LayersPaddedFetch<Cell> {
    uint64_t* skips;
    bool TapsEmpty(uint32_t base) const {
        const bool empty = cpu::HWY_NAMESPACE::LayersPaddedFetch<Cell>::TapsEmpty(base);
        *skips += empty ? 1 : 0;
        return empty;
    }
};

// Every pixel of every camera of `scene`, with and without the skip, over a sparse volume (a voxel in eight cloudy,
// so that whole taps are often empty): the same colours and counts bit for bit; returns the skips taken.
template <class Cell>
uint64_t ComparePixels(const Scene& scene, const std::vector<Cell>& volume, const std::vector<uint64_t>& bits) {
    uint64_t skips = 0;
    for (const CameraSettings& camera : scene.render.cameras) {
        const LayersParams p = MakeLayersParams(scene, camera, 0);
        const LayersSetup& s = p.setup;
        const LayersWalks walks = MakeLayersWalks(s);
        const std::vector<LayersBillboard> list = MakeLayersBillboards(s, p.camera.forward);
        const LayersBillboards billboards{list.data(), uint32_t(list.size()), p.camera.right, p.camera.upVector};
        const PlainFetch<Cell> plain{volume.data()};
        CountingFetch<Cell> fast{{volume.data(), bits.data()}, &skips};
        for (uint32_t y = 0; y < p.camera.height; ++y)
            for (uint32_t x = 0; x < p.camera.width; ++x) {
                const LayersRay ray = MakeLayersRay(p.camera, s.voxelSize, x, y);
                const LayersPixelResult a = LayersPixel(s, walks, ray, plain, billboards);
                const LayersPixelResult b = LayersPixel(s, walks, ray, fast, billboards);
                EXPECT_EQ(a.color, b.color) << camera.name << " (" << x << ", " << y << ")";
                EXPECT_EQ(a.fragments, b.fragments);
                EXPECT_EQ(a.drawn, b.drawn);
                if (a.color != b.color) return skips;
            }
    }
    return skips;
}

TEST(LayersOccupancy, SkippingChangesNoPixel) {
    const std::string path = std::string(CLOUDBENCH_SCENES_DIR) + "/layers-small.json";
    for (const char* tiling : {"true", "false"}) {
        auto scene = LoadScene(
            path,
            {{"grid.tiling", tiling}, {"layers.lod0_radius", "600"}, {"render.width", "64"}, {"render.height", "48"}});
        ASSERT_TRUE(scene.has_value()) << scene.error().message;
        const Extent3 e = scene->grid.size;
        Pcg32 rng(0x0cc0);
        std::vector<float> q(e.Count()), T(e.Count()), skyT(e.Count());
        for (size_t v = 0; v < q.size(); ++v) {
            q[v] = rng.Below(8) == 0 ? float(rng.Uniform(0.05, 1)) : 0.0f;
            T[v] = float(rng.Uniform(0, 1));
            skyT[v] = float(rng.Uniform(0, 1));
        }
        const bool wrap = scene->grid.tiling;
        auto readQ = [](const auto& cell) { return cell[0]; };
        std::vector<std::array<float, 2>> pairs;
        std::vector<uint64_t> bits;
        cpu::HWY_NAMESPACE::FormPaddedVolume(pairs, e, wrap, std::array<float, 2>{0.0f, 1.0f}, [&](size_t v) {
            return std::array<float, 2>{q[v], T[v]};
        });
        cpu::HWY_NAMESPACE::FormEmptyTaps(bits, pairs, e, readQ);
        EXPECT_GT(ComparePixels(*scene, pairs, bits), 1000u) << "tiling " << tiling;
        // The sky light's triples, its term on.
        auto lit = LoadScene(path, {{"grid.tiling", tiling},
                                    {"render.width", "64"},
                                    {"render.height", "48"},
                                    {"stages", R"(["noise", "shade", "shade_sky", "render_layers"])"},
                                    {"lighting.sky", R"({"elevation_deg": 10, "azimuth_deg": 200})"}});
        ASSERT_TRUE(lit.has_value()) << lit.error().message;
        std::vector<std::array<float, 3>> triples;
        cpu::HWY_NAMESPACE::FormPaddedVolume(triples, e, wrap, std::array<float, 3>{0.0f, 1.0f, 1.0f}, [&](size_t v) {
            return std::array<float, 3>{q[v], T[v], skyT[v]};
        });
        cpu::HWY_NAMESPACE::FormEmptyTaps(bits, triples, e, readQ);
        EXPECT_GT(ComparePixels(*lit, triples, bits), 1000u) << "tiling " << tiling << ", the sky light";
    }
}

}  // namespace
}  // namespace cb
