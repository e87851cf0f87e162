// Helpers shared by the tests: canonical upload/download through a backend.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <vector>

#include "core/math/Random.h"
#include "core/pipeline/Backend.h"
#include "core/pipeline/Ellipsoids.h"

namespace cb::test {

// One Gaussian blob of a test field: centre (x, y, z) and sigma, in voxels.
struct TestBlob {
    double x, y, z, sigma;
};

// The sum of Gaussian blobs at voxel centres, clamped to 1, and 0 where it is
// below 1e-3 (so that whole bricks of a ray-march test are empty).
inline std::vector<float> GaussianBlobField(const Extent3& e, std::initializer_list<TestBlob> blobs) {
    std::vector<float> q(e.Count());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) {
                double v = 0;
                for (const TestBlob& b : blobs) {
                    const double dx = i + 0.5 - b.x, dy = j + 0.5 - b.y, dz = k + 0.5 - b.z;
                    v += std::exp(-(dx * dx + dy * dy + dz * dz) / (2 * b.sigma * b.sigma));
                }
                q[VoxelIndex(e, i, j, k)] = v < 1e-3 ? 0.0f : float(std::min(v, 1.0));
            }
    return q;
}

// A bit field's canonical bytes (one 0 or 1 per voxel), each voxel 1 with
// probability 1 / oneIn, from Pcg32(seed).
inline std::vector<uint8_t> RandomBits(const Extent3& e, uint32_t seed, uint32_t oneIn) {
    Pcg32 rng(seed);
    std::vector<uint8_t> bits(e.Count());
    for (uint8_t& b : bits) b = rng.Below(oneIn) == 0 ? 1 : 0;
    return bits;
}

// 25 ellipsoids of random centres (some past the grid's sides), radii and yaw.
inline std::vector<RasterEllipsoid> RandomEllipsoids(const Extent3& e, uint32_t seed) {
    Pcg32 rng(seed);
    std::vector<RasterEllipsoid> list;
    for (int n = 0; n < 25; ++n) {
        const double yaw = rng.Uniform(0, 6.283185307179586);
        list.push_back(
            {{float(rng.Uniform(-5, e.nx + 5)), float(rng.Uniform(-5, e.ny + 5)), float(rng.Uniform(0, e.nz))},
             {float(rng.Uniform(1, 14)), float(rng.Uniform(1, 10)), float(rng.Uniform(1, 5))},
             float(std::cos(yaw)),
             float(std::sin(yaw))});
    }
    return list;
}

inline std::unique_ptr<Buffer> MakeBuffer(Backend& backend, BufferFormat format, Extent3 extent) {
    auto buffer = backend.CreateBuffer(format, extent);
    EXPECT_TRUE(buffer.has_value()) << buffer.error().message;
    return std::move(*buffer);
}

template <typename T>
std::unique_ptr<Buffer> MakeFilled(Backend& backend, BufferFormat format, Extent3 extent, const std::vector<T>& data) {
    auto buffer = MakeBuffer(backend, format, extent);
    Status status = backend.Upload(*buffer, std::as_bytes(std::span(data)));
    EXPECT_TRUE(status.has_value()) << status.error().message;
    return buffer;
}

template <typename T>
std::vector<T> Read(Backend& backend, const Buffer& buffer) {
    std::vector<T> data(buffer.CanonicalBytes() / sizeof(T));
    Status status = backend.Download(buffer, std::as_writable_bytes(std::span(data)));
    EXPECT_TRUE(status.has_value()) << status.error().message;
    return data;
}

}  // namespace cb::test
