// The points of the --vary axes (harness/VaryAxes.h).
#include "harness/VaryAxes.h"

namespace cb {

std::vector<std::vector<SceneOverride>> VaryPoints(const std::vector<SweepAxis>& axes) {
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
