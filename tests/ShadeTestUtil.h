// What the light attenuation tests share (tests/ShadeTest.cpp, tests/ShadeSweepTest.cpp):
// shading on the CPU backend and a normalised sun vector.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/math/Shading.h"
#include "impl_cpu/BackendCpu.h"
#include "tests/TestUtil.h"

namespace cb::test {

// T starts as `initialT` everywhere (NaN: a cell read before it is written shows).
inline std::vector<float> ShadeOnCpu(const Extent3& e, const std::vector<float>& q, const ShadeParams& p,
                                     int threads = 0, float initialT = 0.0f) {
    cpu::BackendCpu backend(threads);
    auto qb = test::MakeFilled(backend, BufferFormat::F32, e, q);
    auto T = test::MakeFilled(backend, BufferFormat::F32, e, std::vector<float>(e.Count(), initialT));
    Status s = backend.Shade(p, *qb, *T);
    EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
    return test::Read<float>(backend, *T);
}

inline Vec3 Normalized(float x, float y, float z) {
    const float l = std::sqrt(x * x + y * y + z * z);
    return {x / l, y / l, z / l};
}

}  // namespace cb::test
