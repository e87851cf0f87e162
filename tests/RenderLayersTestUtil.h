// The cases of the layered renderer's tests (tests/RenderLayersTest.cpp, tests/RenderLayersLod0Test.cpp): a grid
// with both steps' q and T and the call's parameters, its image on a backend, and the two fixtures (every backend;
// the GPU backends against the CPU), instantiated in RenderLayersTest.cpp.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "core/math/Layers.h"
#include "core/pipeline/Backend.h"
#include "tests/BackendTestUtil.h"
#include "tests/MarchTestUtil.h"
#include "tests/TestUtil.h"

namespace cb::test {

struct LayersCase {
    Extent3 grid{12, 10, 6};
    std::vector<float> qPrev, qCur, T;
    LayersParams params;
};

struct LayersImage {
    std::vector<float> rgb;
    LayersStats stats;
    bool ok = false;
};

inline LayersImage RenderLayersOn(Backend& backend, const LayersCase& c) {
    auto qPrev = MakeFilled(backend, BufferFormat::F32, c.grid, c.qPrev);
    auto qCur = MakeFilled(backend, BufferFormat::F32, c.grid, c.qCur);
    auto t = MakeFilled(backend, BufferFormat::F32, c.grid, c.T);
    auto image = MakeBuffer(backend, BufferFormat::F32, {3, c.params.camera.width, c.params.camera.height});
    LayersImage out;
    out.stats = {777, 777};  // garbage, so that a counter the backend forgets to set fails
    const Status status = backend.RenderLayers(c.params, {qPrev.get(), qCur.get(), t.get()}, *image, &out.stats);
    EXPECT_TRUE(status.has_value()) << backend.Name() << ": " << status.error().message;
    out.ok = status.has_value();
    if (out.ok) out.rgb = Read<float>(backend, *image);
    return out;
}

// A camera from eye to target over grid e (h = 1 m, origin 0), N layers, HG 0.6, the sun at (0.7, 0.4) rad.
inline LayersParams CameraLayers(const Extent3& e, std::array<double, 3> eye, std::array<double, 3> target, uint32_t w,
                          uint32_t h, uint32_t count, bool tiling) {
    return LayersFromCamera(CameraParams(e, eye, target, w, h), e, count, tiling);
}

// Blobs that differ between the steps and a T that varies from voxel to voxel, with q = 0 in between.
inline LayersCase BlobLayers(const Extent3& e) {
    LayersCase c;
    c.grid = e;
    const double x = e.nx, y = e.ny, z = e.nz;
    c.qPrev = GaussianBlobField(e, {{0.2 * x, 0.3 * y, 0.4 * z, 2}, {0.8 * x, 0.7 * y, 0.6 * z, 2.5}});
    c.qCur = GaussianBlobField(e, {{0.25 * x, 0.95 * y, 0.5 * z, 2.2}, {0.5 * x, 0.5 * y, 0.5 * z, 1.5}});
    c.T.resize(e.Count());
    for (size_t i = 0; i < c.T.size(); ++i) c.T[i] = 0.3f + 0.7f * float((i * 2654435761u) % 1000) / 1000.0f;
    return c;
}

// q = `q` in both steps and T = 1 everywhere.
inline LayersCase UniformLayers(const Extent3& e, float q) {
    LayersCase c;
    c.grid = e;
    c.qPrev.assign(e.Count(), q);
    c.qCur = c.qPrev;
    c.T.assign(e.Count(), 1.0f);
    return c;
}

class RenderLayersAll : public BackendTest {
  protected:
    void SetUp() override {
        BackendTest::SetUp();
        if (IsSkipped()) return;
        ASSERT_TRUE(mBackend->Supports(Stage::RenderLayers));
    }
};

// The three eyes of SPEC 15's order rule over a grid of height nz: below, inside (between layer planes) and above.
inline std::vector<std::array<double, 3>> Eyes(const Extent3& e) {
    return {{0.3 * e.nx, -0.5 * e.ny, -0.7 * e.nz},
            {0.4 * e.nx, 0.45 * e.ny, 0.43 * e.nz},
            {0.2 * e.nx, 0.1 * e.ny, 2.4 * e.nz}};
}

// The GPU backends, each against the CPU.
class RenderLayersGpu : public BackendTest {};

}  // namespace cb::test
