// The generic half of SPEC 12's suite (tests/Spec12ExtremesTest.cpp, tests/Spec12SoakTest.cpp):
// one backend per name for the whole run, and every output array of a step
// downloaded in canonical form and checked against its documented range.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"

namespace cb::spec12_test {

// One backend per name for the whole run (an OpenGL context or a Vulkan
// device is slow to make on llvmpipe); nullptr with the reason when it cannot start.
Backend* BackendFor(const std::string& name, std::string& whyNot);

// The outputs of one step, canonical, as float (bytes widened): current[r][camera].
struct Snapshot {
    uint32_t step = 0;
    std::optional<uint32_t> coveredColumns;
    std::array<std::vector<std::vector<float>>, kResourceCount> current;
    const std::vector<float>& Of(Resource r, size_t camera = 0) const { return current[size_t(r)].at(camera); }
    bool Has(Resource r) const { return !current[size_t(r)].empty(); }
};

// A buffer's canonical data as float (bytes widened).
std::vector<float> DownloadAsFloat(Backend& backend, const Buffer& buffer);

// Checks one array: finite, within the resource's documented range, 0/1 where
// it is a flag, and for T (docs/pipeline.md "No subnormals") 0 or at least 1e-30.
void CheckArray(Resource r, const Scene& s, const std::vector<float>& values, const std::string& what);

// Downloads and checks every output of every enabled stage: each resource an
// enabled stage writes (one buffer per camera for images), and the previous
// step's copy where one is kept. Counts the arrays checked.
Snapshot CheckEveryOutput(const Simulation& sim, uint32_t step, std::optional<uint32_t> cover, size_t& arraysChecked);

}  // namespace cb::spec12_test
