// The axes of --vary PATH=V1,V2,... and their points, shared by `cloudbench
// sweep` (harness/commands/SweepCommand.cpp, which parses them: ParseVaryAxes in
// harness/commands/SweepOutput.h) and `cloudbench conform --vary`
// (harness/conform/ConformMatrix.h). In the harness library, so that ConformMatrix needs
// nothing from the commands.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/scene/Scene.h"

namespace cb {

// One --vary field and its values, in the order given.
struct SweepAxis {
    std::string path;
    std::vector<std::string> values;
};

// The most points a --vary product may have. Each point is a scene loaded and
// checked before anything runs, then measured on every backend: 100 000 points
// of the smallest scene take hours per backend, and their settings about 64 MiB.
inline constexpr uint64_t kMaxVaryPoints = 100000;

// The number of points of the axes' product, without overflow: UINT64_MAX when
// it does not fit in 64 bits.
uint64_t VaryPointCount(const std::vector<SweepAxis>& axes);

// "--vary: N points (10 x 10 x ...), more than the 100000 a sweep may have"
// when the product is too large, else nullopt.
std::optional<std::string> VaryTooLarge(const std::vector<SweepAxis>& axes);

// The cartesian product of the axes' values, the last axis fastest: one list of
// overrides per point; no axes: one empty point. At most kMaxVaryPoints points:
// callers check VaryTooLarge first.
std::vector<std::vector<SceneOverride>> VaryPoints(const std::vector<SweepAxis>& axes);

}  // namespace cb
