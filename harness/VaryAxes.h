// The axes of --vary PATH=V1,V2,... and their points, shared by `cloudbench
// sweep` (harness/commands/SweepCommand.cpp, which parses them: ParseVaryAxes in
// harness/commands/SweepOutput.h) and `cloudbench conform --vary`
// (harness/ConformMatrix.h). In the harness library, so that ConformMatrix needs
// nothing from the commands.
#pragma once

#include <string>
#include <vector>

#include "core/Scene.h"

namespace cb {

// One --vary field and its values, in the order given.
struct SweepAxis {
    std::string path;
    std::vector<std::string> values;
};

// The cartesian product of the axes' values, the last axis fastest: one list of
// overrides per point; no axes: one empty point.
std::vector<std::vector<SceneOverride>> VaryPoints(const std::vector<SweepAxis>& axes);

}  // namespace cb
