// The GPU pass extents test (GpuExtentsTest.cpp, docs/testing.md "GPU pass
// extents"): each case is one stage run on a GPU backend and on the CPU from the
// same inputs, compared by the stage's rule, at a size chosen so that the
// extent one pass dispatches over (or draws, on gl) lands one below, on or one
// above a multiple of its workgroup or tile. The runners are in
// GpuExtentsRunners.cpp (the simulation stages) and GpuExtentsRender.cpp (the
// renderers).
#pragma once

#include <cstdint>
#include <string>

#include "core/pipeline/Backend.h"
#include "core/scene/Stage.h"

namespace cb::extents {

// One size of one pass: the grid, the image (renderers), and one stage-specific choice:
//   ca: 1 = a wind shift on every slice (the advect pass runs); smooth: the radius;
//   density: the tile; shade: the resolution f, +100 for vk's block sweep (shade_block.comp);
//   render_splat: vk's ranks per chunk (0: the default), +1000 for skipping with tile 2 and band 1;
//   render_march: the brick (0: skipping off); render_layers: 1 = tiling.
struct ExtentCase {
    Extent3 grid;
    uint32_t width = 16, height = 12;
    uint32_t option = 0;
};

// Runs `stage` on `gpu` and on the CPU backend from the same inputs at `c` and
// expects the outputs equal by the stage's rule (bit for bit for the integer
// stages and wherever the existing tests require it, SPEC's tolerance otherwise).
// The renderers run a larger volume first on the same backend, so that memory a
// pass fails to write holds the earlier call's values instead of zeros.
void RunExtentCase(Stage stage, Backend& gpu, const ExtentCase& c);

// The simulation stages' and the renderers' halves of RunExtentCase.
void RunSimulationExtentCase(Stage stage, Backend& gpu, const ExtentCase& c);
void RunRenderExtentCase(Stage stage, Backend& gpu, const ExtentCase& c);

std::string Describe(const ExtentCase& c);

}  // namespace cb::extents
