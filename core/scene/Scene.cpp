// The scene's own computations: the sun at a step of the run. Loading is in
// core/plan/SceneLoad.cpp.
#include "core/scene/Scene.h"

#include <cstdint>

#include "core/math/Keyframes.h"

namespace cb {

double SunSettings::ElevationAt(uint32_t step) const {
    if (path.empty()) return elevationDeg + elevationSpeedDeg * double(step);
    return KeyframesAt(path, step, [](const SunKeyframe& k) { return k.elevationDeg; });
}

double SunSettings::AzimuthAt(uint32_t step) const {
    if (path.empty()) return azimuthDeg + azimuthSpeedDeg * double(step);
    return KeyframesAt(path, step, [](const SunKeyframe& k) { return k.azimuthDeg; });
}

}  // namespace cb
