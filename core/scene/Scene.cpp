// The scene's own computations: the sun at a step of the run. Loading is in
// core/plan/SceneLoad.cpp.
#include "core/scene/Scene.h"

#include <cstdint>

namespace cb {

double SunSettings::ElevationAt(uint32_t step) const {
    if (path.empty()) return elevationDeg + elevationSpeedDeg * double(step);
    if (step <= path.front().step) return path.front().elevationDeg;
    if (step >= path.back().step) return path.back().elevationDeg;
    size_t b = 1;
    while (path[b].step < step) ++b;
    const SunKeyframe &lo = path[b - 1], &hi = path[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return lo.elevationDeg + (hi.elevationDeg - lo.elevationDeg) * w;
}

double SunSettings::AzimuthAt(uint32_t step) const {
    if (path.empty()) return azimuthDeg + azimuthSpeedDeg * double(step);
    if (step <= path.front().step) return path.front().azimuthDeg;
    if (step >= path.back().step) return path.back().azimuthDeg;
    size_t b = 1;
    while (path[b].step < step) ++b;
    const SunKeyframe &lo = path[b - 1], &hi = path[b];
    const double w = double(step - lo.step) / double(hi.step - lo.step);
    return lo.azimuthDeg + (hi.azimuthDeg - lo.azimuthDeg) * w;
}

}  // namespace cb
