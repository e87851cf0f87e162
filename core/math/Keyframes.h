// Values keyed by step, linear between keyframes and held before the first and after the last: the sun's path
// (core/scene/Scene.cpp) and a placed ellipsoid's centre (core/pipeline/Ellipsoids.cpp) share this rule.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace cb {

// a + (b - a) w, per component for arrays.
inline double KeyframeMix(double a, double b, double w) { return a + (b - a) * w; }
template <size_t N>
std::array<double, N> KeyframeMix(const std::array<double, N>& a, const std::array<double, N>& b, double w) {
    std::array<double, N> out{};
    for (size_t i = 0; i < N; ++i) out[i] = KeyframeMix(a[i], b[i], w);
    return out;
}

// field(key) at `step` over `keys` (not empty, increasing `step` members): field of the first key at or before
// its step, of the last at or after its step, else KeyframeMix of the two keys around `step`.
template <class Key, class Field>
auto KeyframesAt(const std::vector<Key>& keys, uint32_t step, Field&& field) {
    if (step <= keys.front().step) return field(keys.front());
    if (step >= keys.back().step) return field(keys.back());
    size_t b = 1;
    while (keys[b].step < step) ++b;
    const Key &lo = keys[b - 1], &hi = keys[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return KeyframeMix(field(lo), field(hi), w);
}

}  // namespace cb
