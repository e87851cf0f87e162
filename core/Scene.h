// A scene: what to simulate and which stages to run. Loaded from JSON by
// LoadScene(), which validates every field before any work is done. The fields,
// their units and defaults are documented in docs/scenes.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/Error.h"
#include "core/Grid.h"
#include "core/Stage.h"

namespace cb {

struct GridSettings {
    Extent3 size{64, 16, 64};
    double voxelSize = 50.0;                 // metres per voxel edge (h)
    std::array<double, 3> origin{0, 0, 0};   // world position of voxel corner (0,0,0), metres
};

// Per-slice integer wind shift for Dobashi advection, in voxels per step.
struct SliceShift {
    int32_t sx = 0, sy = 0;
};

struct CaSettings {
    uint32_t seed = 1;
    double hum0 = 0.35;   // initial humidity probability
    double act0 = 0.001;  // initial activation probability
    double pExt = 0.1;
    double pHum = 0.1;
    double pAct = 0.001;
    // Empty: no advection. Otherwise exactly nz entries (a one-entry list in
    // the file is expanded to every slice).
    std::vector<SliceShift> windShift;

    bool HasWind() const {
        for (const SliceShift& s : windShift)
            if (s.sx != 0 || s.sy != 0) return true;
        return false;
    }
};

// Horizontal wind that moves the ellipsoids, in voxels per step: one vector, or
// a grid of vectors spread over the region bounds and looked up bilinearly.
struct EllipsoidWind {
    std::array<double, 2> vector{0, 0};
    uint32_t gridNx = 0, gridNy = 0;            // 0: use `vector`
    std::vector<std::array<double, 2>> grid;    // gridNx*gridNy, x fastest
};

struct EllipsoidSettings {
    uint64_t seed = 1;
    uint32_t targetCount = 40;
    uint32_t densityAdaption = 2;                 // most added or removed per step
    std::array<double, 3> sizeMean{16, 16, 8};    // semi-axes in voxels
    std::array<double, 3> sizeVariance{4, 4, 2};  // uniform +- around the mean
    double lifetimeMean = 400;                    // steps
    double lifetimeVariance = 100;
    uint32_t shrinkSteps = 40;
    double margin = 16;                           // voxels added around the grid (region bounds)
    std::array<double, 2> heightRange{0.25, 0.5}; // centre height, fraction of nz
    EllipsoidWind wind;
    double jitter = 0.05;                         // uniform +- per axis per step, voxels
};

struct SmoothSettings {
    int radius = 1;  // 0, 1 or 2
};

struct DensitySettings {
    uint32_t tile = 32;  // tile edge in columns
    uint32_t band = 4;   // slices per height band
};

struct Scene {
    std::string name;
    std::string path;  // file it was read from ("" for built-in)
    GridSettings grid;
    uint32_t steps = 20;
    uint32_t warmupSteps = 0;  // leading steps left out of timing and cover statistics
    StageSet stages;
    CaSettings ca;
    EllipsoidSettings ellipsoids;
    SmoothSettings smooth;
    DensitySettings density;
};

// One --set PATH=VALUE override, applied to the JSON before validation.
struct SceneOverride {
    std::string path;   // dotted, e.g. "ca.seed" or "grid.size"
    std::string value;  // JSON text; a bare word is taken as a string
};

// Reads, overrides and validates a scene. Errors read "file: field: reason",
// one per line, every problem found (not just the first).
Result<Scene> LoadScene(const std::string& path, const std::vector<SceneOverride>& overrides = {});

// Same, from JSON text (for tests); `label` stands in for the file name.
Result<Scene> ParseScene(const std::string& text, const std::string& label,
                         const std::vector<SceneOverride>& overrides = {});

// Bytes the scene's enabled stages allocate on the CPU backend (for the memory check).
uint64_t EstimateSceneBytes(const Scene& scene);

}  // namespace cb
