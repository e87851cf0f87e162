// The points of the --vary axes (harness/run/VaryAxes.h).
#include "harness/run/VaryAxes.h"

#include <cassert>

namespace cb {

uint64_t VaryPointCount(const std::vector<SweepAxis>& axes) {
    uint64_t count = 1;
    for (const SweepAxis& axis : axes) {
        const uint64_t n = axis.values.size();
        if (n != 0 && count > UINT64_MAX / n) return UINT64_MAX;
        count *= n;
    }
    return count;
}

std::optional<std::string> VaryTooLarge(const std::vector<SweepAxis>& axes) {
    const uint64_t count = VaryPointCount(axes);
    if (count <= kMaxVaryPoints) return std::nullopt;
    std::string product;
    for (const SweepAxis& axis : axes) product += (product.empty() ? "" : " x ") + std::to_string(axis.values.size());
    return "--vary: " + (count == UINT64_MAX ? std::string("more than 2^64") : std::to_string(count)) + " points (" +
           product + "), more than the " + std::to_string(kMaxVaryPoints) + " a sweep may have";
}

std::vector<std::vector<SceneOverride>> VaryPoints(const std::vector<SweepAxis>& axes) {
    assert(VaryPointCount(axes) <= kMaxVaryPoints);
    std::vector<std::vector<SceneOverride>> points = {{}};
    for (const SweepAxis& axis : axes) {
        std::vector<std::vector<SceneOverride>> next;
        for (const auto& p : points)
            for (const std::string& v : axis.values) {
                auto q = p;
                q.push_back({axis.path, v});
                next.push_back(std::move(q));
            }
        points = std::move(next);
    }
    return points;
}

}  // namespace cb
