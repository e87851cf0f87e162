// The 90-degree rotation about z, shared by
// tests/MetamorphicRotationTest.cpp (the mapping, the automaton and the field
// stages) and tests/MetamorphicRotationImageTest.cpp (shade, shadow and the
// renderers): the mapping and the fixtures.
//
// The mapping: voxel (i, j, k) of an nx x ny x nz
// grid is voxel (ny-1-j, i, k) of the turned ny x nx x nz grid; a world point
// P goes to O + Rz90 (P - O) + (ny h, 0, 0), a direction d to Rz90 d, with
// Rz90 (x, y, z) = (-y, x, z). Outputs of the turned scene are turned back
// (RotUnrotate) and compared with the plain scene's.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/math/Grid.h"
#include "core/math/Shading.h"
#include "core/plan/StageGraph.h"
#include "tests/BackendTestUtil.h"

namespace cb {

// ---- The mapping, written once -------------------------------------------------

inline Extent3 RotExtent(const Extent3& e) { return {e.ny, e.nx, e.nz}; }

// Where voxel (i, j, k) of grid e lies in the turned grid RotExtent(e).
inline uint32_t RotIndex(const Extent3& e, uint32_t i, uint32_t j, uint32_t k) {
    return VoxelIndex(RotExtent(e), e.ny - 1 - j, i, k);
}

// A field of grid e, turned: out[RotIndex(e, i, j, k)] = f[(i, j, k)].
template <typename T>
std::vector<T> RotRotate(const Extent3& e, const std::vector<T>& f) {
    std::vector<T> out(f.size());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) out[RotIndex(e, i, j, k)] = f[VoxelIndex(e, i, j, k)];
    return out;
}

// A field of the turned grid RotExtent(e), turned back to grid e.
template <typename T>
std::vector<T> RotUnrotate(const Extent3& e, const std::vector<T>& g) {
    std::vector<T> out(g.size());
    for (uint32_t k = 0; k < e.nz; ++k)
        for (uint32_t j = 0; j < e.ny; ++j)
            for (uint32_t i = 0; i < e.nx; ++i) out[VoxelIndex(e, i, j, k)] = g[RotIndex(e, i, j, k)];
    return out;
}

// Directions (the sun, up): Rz90.
inline Vec3 RotVec(const Vec3& d) { return {-d[1], d[0], d[2]}; }
// World points of a grid with origin 0 and voxel size h: (x, y, z) -> (ny h - y, x, z).
inline std::array<double, 3> RotPoint(const Extent3& e, double h, const std::array<double, 3>& p) {
    return {e.ny * h - p[1], p[0], p[2]};
}

// Float fields: the largest |a - b|.
inline float RotMaxDiff(const std::vector<float>& a, const std::vector<float>& b) {
    EXPECT_EQ(a.size(), b.size());
    float m = 0;
    for (size_t n = 0; n < std::min(a.size(), b.size()); ++n) m = std::max(m, std::fabs(a[n] - b[n]));
    return m;
}

class Rotation : public test::BackendTest {
  protected:
    void Need(Stage stage) {
        if (!mBackend->Supports(stage))
            GTEST_SKIP() << "unsupported here: " << mBackend->Name() << " has no " << StageName(stage);
    }
};
class RotationCa : public Rotation {};

}  // namespace cb
