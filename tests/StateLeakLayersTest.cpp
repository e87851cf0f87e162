// No state leaks between renderer calls on a GPU backend: a tiled render_layers
// call (the padded volume's border wrapped: march_volume's `wrap`), or one with
// every other option on (wang opacity, drift, Mie, other layer counts), leaves
// nothing behind that changes the next untiled render_layers or render_march
// call, which share march_volume's program on gl. A render_march call with its
// own options (brick 1, light "march", jitter, Mie) likewise leaves nothing for
// the next. Each second call equals the same call on a fresh backend bit for
// bit (lavapipe and llvmpipe are deterministic for the same inputs and calls).
// tests/StateLeakTest.cpp does the same for whole scenes, which never change
// tiling or the marcher's options within a process.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <functional>
#include <vector>

#include "core/math/Random.h"
#include "tests/BackendTestUtil.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb {
namespace {

const Extent3 kLeakGrid{14, 11, 6};

// q in [0.35, 0.85] everywhere, differing between the steps and from column to column, so that the wrapped border
// (the opposite edge) differs from the plain one (0, 1); T in [0.3, 1].
struct LeakVolumes {
    std::vector<float> qPrev, qCur, T;
};
LeakVolumes MakeLeakVolumes(const Extent3& e) {
    LeakVolumes v;
    for (size_t i = 0; i < e.Count(); ++i) {
        v.qPrev.push_back(0.35f + float(LowBias32(uint32_t(i) + 3u) % 501u) / 1000.0f);
        v.qCur.push_back(0.35f + float(LowBias32(uint32_t(i) + 4242u) % 501u) / 1000.0f);
        v.T.push_back(0.3f + float(LowBias32(uint32_t(i) * 5u) % 701u) / 1000.0f);
    }
    return v;
}

// A renderer call on a backend: the image it writes.
using LeakCall = std::function<std::vector<float>(Backend&)>;

// The eye above the grid, looking down at all of it (every edge, where the border is sampled), W x H pixels.
MarchParams LeakCamera(uint32_t w, uint32_t h) {
    const Extent3 e = kLeakGrid;
    return test::CameraParams(e, {0.3 * e.nx, -0.2 * e.ny, 3.0 * e.nz + 12}, {0.5 * e.nx, 0.5 * e.ny, 0}, w, h);
}

LayersParams LeakLayersParams(bool tiling) {
    return test::LayersFromCamera(LeakCamera(33, 25), kLeakGrid, kLeakGrid.nz, tiling);
}

std::vector<float> LeakRenderLayers(Backend& b, const LayersParams& p) {
    const LeakVolumes v = MakeLeakVolumes(kLeakGrid);
    auto qPrev = test::MakeFilled(b, BufferFormat::F32, kLeakGrid, v.qPrev);
    auto qCur = test::MakeFilled(b, BufferFormat::F32, kLeakGrid, v.qCur);
    auto t = test::MakeFilled(b, BufferFormat::F32, kLeakGrid, v.T);
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, p.camera.width, p.camera.height});
    LayersStats stats;
    const Status s = b.RenderLayers(p, {qPrev.get(), qCur.get(), t.get()}, *image, &stats);
    EXPECT_TRUE(s.has_value()) << b.Name() << ": " << s.error().message;
    return s ? test::Read<float>(b, *image) : std::vector<float>{};
}

std::vector<float> LeakRenderMarch(Backend& b, const MarchParams& p) {
    const LeakVolumes v = MakeLeakVolumes(kLeakGrid);
    auto qPrev = test::MakeFilled(b, BufferFormat::F32, kLeakGrid, v.qPrev);
    auto qCur = test::MakeFilled(b, BufferFormat::F32, kLeakGrid, v.qCur);
    auto t = test::MakeFilled(b, BufferFormat::F32, kLeakGrid, v.T);
    auto image = test::MakeBuffer(b, BufferFormat::F32, {3, p.camera.width, p.camera.height});
    MarchStats stats;
    const MarchInputs in{qPrev.get(), qCur.get(), p.light == MarchLightSource::Shade ? t.get() : nullptr};
    const Status s = b.RenderMarch(p, in, *image, &stats);
    EXPECT_TRUE(s.has_value()) << b.Name() << ": " << s.error().message;
    return s ? test::Read<float>(b, *image) : std::vector<float>{};
}

MarchParams LeakPlainMarch() {
    MarchParams p = LeakCamera(29, 23);
    p.setup.epsilon = 0.01f;
    p.alpha = 0.3f;
    return p;
}

// Every option render_march has that a call can change: brick 1, light "march", jitter, Mie, adaptive steps.
MarchParams LeakOtherMarch() {
    MarchParams p = LeakPlainMarch();
    p.brick = 1;
    p.light = MarchLightSource::March;
    p.jitter = true, p.seed = 5, p.frame = 3;
    p.setup.light.phase = {PhaseKind::Mie, 0};
    p.setup.adaptive = true, p.setup.kappa = 0.1f;
    p.alpha = 0.8f;
    return p;
}

// Every option render_layers has besides tiling: wang opacity, drift, Mie, another layer count and l_max.
LayersParams LeakOtherLayers(const std::vector<float>& map) {
    LayersParams p = LeakLayersParams(true);
    LayersSetup& s = p.setup;
    s.wang = true, s.coverage = 0.9f, s.density = 3.0f, s.map = map.data();
    s.drift = {1.37f, -0.61f};
    s.light.phase = {PhaseKind::Mie, 0};
    s.count = 2 * kLeakGrid.nz, s.spacing = 0.5f, s.maxLength = 2.5f;
    p.alpha = 0.9f;
    return p;
}

class StateLeakLayers : public test::BackendTest {
  protected:
    // Expects `after` on this backend, run after `before`, to equal `after` on a fresh backend, bit for bit.
    void ExpectNoLeak(const char* what, const LeakCall& before, const LeakCall& after) {
        auto fresh = test::MakeTestBackend(GetParam());
        ASSERT_TRUE(fresh.has_value()) << fresh.error().message;
        const std::vector<float> want = after(**fresh);
        test::ExpectNoValidationMessages(fresh->get());
        fresh->reset();
        (void)before(*mBackend);
        const std::vector<float> got = after(*mBackend);
        ASSERT_FALSE(want.empty());
        ASSERT_EQ(got.size(), want.size()) << what;
        size_t differ = 0, first = 0;
        for (size_t i = got.size(); i-- > 0;)
            if (std::bit_cast<uint32_t>(got[i]) != std::bit_cast<uint32_t>(want[i])) ++differ, first = i;
        EXPECT_EQ(differ, 0u) << what << ": " << differ << " of " << got.size() << " channels differ from a fresh "
                              << "backend's; first " << first << ": " << got[first] << " vs " << want[first];
    }
};

// Test that an untiled render_layers call after a tiled one equals it on a fresh backend (the wrap does not stay).
TEST_P(StateLeakLayers, UntiledLayersAfterTiledEqualsAFreshBackend) {
    ExpectNoLeak(
        "untiled render_layers after a tiled one",
        [](Backend& b) { return LeakRenderLayers(b, LeakLayersParams(true)); },
        [](Backend& b) { return LeakRenderLayers(b, LeakLayersParams(false)); });
}

// Test the other way round, and that the two differ at all (else the tests above prove nothing).
TEST_P(StateLeakLayers, TiledLayersAfterUntiledEqualsAFreshBackendAndDiffers) {
    ExpectNoLeak(
        "tiled render_layers after an untiled one",
        [](Backend& b) { return LeakRenderLayers(b, LeakLayersParams(false)); },
        [](Backend& b) { return LeakRenderLayers(b, LeakLayersParams(true)); });
    EXPECT_NE(LeakRenderLayers(*mBackend, LeakLayersParams(false)), LeakRenderLayers(*mBackend, LeakLayersParams(true)))
        << "tiling changes nothing on this grid: the leak tests would pass for nothing";
}

// Test that a plain untiled render_layers call after one with every other option equals it on a fresh backend.
TEST_P(StateLeakLayers, PlainLayersAfterEveryOptionEqualsAFreshBackend) {
    std::vector<float> map(size_t(kLeakGrid.nx) * kLeakGrid.ny);
    for (size_t i = 0; i < map.size(); ++i) map[i] = float((i * 2654435761u) % 997) / 2000.0f;
    ExpectNoLeak(
        "render_layers after wang, drift, Mie",
        [&map](Backend& b) { return LeakRenderLayers(b, LeakOtherLayers(map)); },
        [](Backend& b) { return LeakRenderLayers(b, LeakLayersParams(false)); });
}

// Test that render_march after a tiled render_layers call (gl: the same march_volume program) equals it on a fresh
// backend: its border stays (0, 1).
TEST_P(StateLeakLayers, MarchAfterTiledLayersEqualsAFreshBackend) {
    ExpectNoLeak(
        "render_march after a tiled render_layers",
        [](Backend& b) { return LeakRenderLayers(b, LeakLayersParams(true)); },
        [](Backend& b) { return LeakRenderMarch(b, LeakPlainMarch()); });
}

// Test that render_march with its defaults after a call with every other option equals it on a fresh backend.
TEST_P(StateLeakLayers, PlainMarchAfterEveryOptionEqualsAFreshBackend) {
    ExpectNoLeak(
        "render_march after brick 1, light march, jitter, Mie, adaptive",
        [](Backend& b) { return LeakRenderMarch(b, LeakOtherMarch()); },
        [](Backend& b) { return LeakRenderMarch(b, LeakPlainMarch()); });
}

INSTANTIATE_TEST_SUITE_P(Backends, StateLeakLayers, ::testing::ValuesIn(test::GpuTestBackends()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace cb
