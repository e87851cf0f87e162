// The items' own properties for SPEC 12's suite (tests/Spec12ExtremesTest.cpp),
// each hand-derived from docs/contract.md and docs/pipeline.md, and the scene values
// the items are built from. Defined in tests/Spec12Checks.cpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/scene/Scene.h"
#include "harness/run/Simulation.h"
#include "tests/Spec12Outputs.h"

namespace cb::spec12_test {

// What an item's check sees at one step.
struct ItemContext {
    const Scene& scene;
    const Simulation& sim;
    Backend& backend;
    const Snapshot& now;    // this step's outputs
    const Snapshot& first;  // step 0's outputs
};

// Every item runs kSteps steps from step 0.
constexpr uint32_t kSteps = 3;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

// `v` with 17 significant digits, as a scene value.
std::string Num(double v);

// Scene values that make the region R = 255 in every voxel.
std::vector<SceneOverride> FullRegion();
// With FullRegion: cld = 1 everywhere and hum = act = 0 from step 1 on, a completely full volume.
std::vector<SceneOverride> FullVolume();
// a, then b.
std::vector<SceneOverride> Plus(std::vector<SceneOverride> a, const std::vector<SceneOverride>& b);

// Every value equals `expected`; the failure counts those that differ and names the first.
void ExpectAll(const std::vector<float>& values, float expected, const std::string& what);
// Largest |a - b| over two arrays (NaN counts as infinite).
double WorstDifference(const std::vector<float>& a, const std::vector<double>& b);

// Sun straight overhead (up) or below: T and G against the hand-computed columns.
void CheckVerticalSun(const ItemContext& c, bool up);
// Sun straight overhead or below with sigma huge: T is 0 below cloud, 1 on clear paths.
void CheckOpaqueColumns(const ItemContext& c, bool up);
// A full volume (FullVolume): the automaton's bits, the cover, q, D and T exactly.
void CheckFullVolume(const ItemContext& c);
// Occupancy, cover and D recomputed from the downloaded q and cld, on partial tiles and bands.
void CheckDensityOnPartialTiles(const ItemContext& c);
// The sun 1e-6 rad either side of a switch of the principal axis: T jumps by at most the documented bound.
void CheckAcrossSwitch(const ItemContext& c, double elevation, double azimuth, bool alongElevation);
// T stored as fp16 or unorm8 holds codes of the format.
void CheckStorageCodes(const ItemContext& c);

// The cameras CheckCameras expects, as render.cameras JSON for a grid `e` of voxel size `h`.
std::string CamerasJson(const Extent3& e, double h);
// Looking straight down or up with the degenerate up vector gives the image of its +y twin.
void CheckCameras(const ItemContext& c);

}  // namespace cb::spec12_test
