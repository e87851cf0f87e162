// libFuzzer target over the scene parser, `--set` overrides and the stage-parameter setup (docs/fuzzing.md).
// Built only in the sanitized clang sub-build (cmake/Sanitized.cmake).
//
// Input format: the scene's JSON text, then optionally one NUL byte followed by `--set` overrides, one per
// line, each PATH=VALUE split at the first '=' exactly as the command line splits `--set` (a line without
// '=' or starting with '=' is skipped, as the command line refuses it before loading). Example:
//   {"grid": {"size": [8, 4, 8]}}\0steps=3\nca.seed=42
//
// For a scene that validates, every host-side derivation a run makes before touching a backend is done:
// the buffer plan and its byte counts, each stage's parameters (Make*Params), the shade plan, and per
// camera the splat frame. The grid-sized host work (the splat order, frustum culling, the ellipsoid list)
// is only done for small grids and ellipsoid counts, so that one input stays well under the -timeout.
// Contract: no crash, no sanitizer report, no leak, and the invariants below hold; a broken invariant traps.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "core/math/Camera.h"
#include "core/math/Splat.h"
#include "core/pipeline/Ellipsoids.h"
#include "core/pipeline/ShadePlan.h"
#include "core/pipeline/SplatFrame.h"
#include "core/plan/MemoryPlan.h"
#include "core/plan/SceneLoad.h"
#include "core/plan/StageGraph.h"
#include "core/scene/Scene.h"
#include "core/stages/ca/Ca.h"
#include "core/stages/density/Density.h"
#include "core/stages/render_splat/RenderSplat.h"
#include "core/stages/shade/Shade.h"
#include "core/stages/shadow/Shadow.h"

namespace {

using namespace cb;

// The most voxels (and tile-band boxes) for which the grid-sized host work runs per input.
constexpr uint64_t kMaxHostWorkVoxels = uint64_t(1) << 20;
// The most ellipsoids simulated per input (the validator allows 100,000; each costs a few doubles).
constexpr uint32_t kMaxHostWorkEllipsoids = 2000;
// Inputs larger than this are ignored: the loader's own limit is 16 MiB, and libFuzzer's default -max_len is far
// below; this only keeps a hand-made crash file from taking minutes.
constexpr size_t kMaxInputBytes = size_t(1) << 20;

// Fails loudly: an invariant of the derived sizes does not hold for a scene the validator accepted.
[[noreturn]] void Broken(const char* what) {
    std::fprintf(stderr, "SceneFuzzer: invariant broken: %s\n", what);
    std::abort();
}

void Require(bool holds, const char* what) {
    if (!holds) Broken(what);
}

std::vector<SceneOverride> ParseOverrides(std::string_view text) {
    std::vector<SceneOverride> out;
    while (!text.empty()) {
        const size_t end = text.find('\n');
        const std::string_view line = text.substr(0, end);
        text = end == std::string_view::npos ? std::string_view() : text.substr(end + 1);
        const size_t eq = line.find('=');
        if (eq == std::string_view::npos || eq == 0) continue;  // the command line refuses these (exit 2)
        out.push_back({std::string(line.substr(0, eq)), std::string(line.substr(eq + 1))});
    }
    return out;
}

// The tile-band count along one edge: at least one, and count * size covers the edge (no 32-bit wrap).
void RequireCovers(uint32_t edge, uint32_t size, const char* what) {
    Require(size >= 1, what);
    const uint32_t count = CeilDiv(edge, size);
    Require(count >= 1 && uint64_t(count) * size >= edge && uint64_t(count - 1) * size < edge, what);
}

void SetUpStages(const Scene& scene) {
    const Extent3& grid = scene.grid.size;
    Require(grid.nx >= 1 && grid.ny >= 1 && grid.nz >= 1 && grid.Count() <= UINT32_MAX, "grid extent");

    // The buffer plan and its prices: every planned buffer non-empty (a backend refuses empty buffers).
    (void)ScheduleStages(scene.stages);
    (void)PlanResources(scene);
    const std::vector<PlannedBuffer> buffers = PlanBuffers(scene);
    const uint64_t total = EstimateSceneBytes(scene);
    const uint64_t staging = HostStagingBytes(scene);
    Require(total >= staging, "EstimateSceneBytes >= HostStagingBytes");
    for (const PlannedBuffer& b : buffers) {
        Require(b.extent.nx >= 1 && b.extent.ny >= 1 && b.extent.nz >= 1, "planned buffer not empty");
        Require(HostBufferBytes(b.format, b.extent) <= total, "a buffer's bytes within the total");
        Require(CanonicalBufferBytes(b.format, b.extent) <= staging, "staging holds every buffer");
    }

    // Each stage's parameters, whether or not the stage is enabled (the CLI's --set can enable any).
    (void)MakeCaInitParams(scene);
    (void)MakeCaStepParams(scene, 0);
    (void)MakeCaStepParams(scene, scene.steps - 1);
    const DensityParams density = MakeDensityParams(scene);
    RequireCovers(grid.nx, density.tile, "density tiles cover nx");
    RequireCovers(grid.ny, density.tile, "density tiles cover ny");
    RequireCovers(grid.nz, density.band, "density bands cover nz");
    const ShadeParams shade = MakeShadeParams(scene);
    const ShadePlan plan = MakeShadePlan(shade, grid);
    for (int axis = 0; axis < 3; ++axis) Require(plan.cells[axis] >= 1, "shade plan cells");
    Require(uint64_t(plan.nu) * plan.nv * plan.nw <= grid.Count(), "shade plan within the grid");
    (void)MakeShadowParams(scene);

    const bool smallGrid = grid.Count() <= kMaxHostWorkVoxels;
    for (const CameraSettings& camera : scene.render.cameras) {
        SplatParams p = MakeSplatParams(scene, camera);
        if (!smallGrid) continue;
        const SplatOrder order = MakeSplatOrder(p.camera, grid, scene.grid.origin, scene.grid.voxelSize);
        p.order = &order;
        const FlatSplatOrder flat = FlattenSplatOrder(order);
        Require(flat.indices.size() == uint64_t(grid.nx) + grid.ny + grid.nz, "splat order covers every axis");
        (void)MakeSplatFrame(p, grid, flat, scene.render.width, scene.render.height);
        const std::vector<uint8_t> boxes =
            FrustumVisibleBoxes(p.camera, grid, p.origin, p.voxelSize, p.tile, p.band, p.splatDiameter);
        Require(boxes.size() ==
                    uint64_t(CeilDiv(grid.nx, p.tile)) * CeilDiv(grid.ny, p.tile) * CeilDiv(grid.nz, p.band),
                "one culling flag per tile-band box");
    }

    // The region stage's host input: the ellipsoid list, two steps of it, and its raster form.
    if (smallGrid && scene.ellipsoids.targetCount <= kMaxHostWorkEllipsoids &&
        scene.ellipsoids.densityAdaption <= kMaxHostWorkEllipsoids) {
        EllipsoidList list(scene.ellipsoids, grid);
        list.Update();
        list.Update();
        (void)list.Raster();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size > kMaxInputBytes) return -1;  // not added to the corpus
    const std::string_view input(reinterpret_cast<const char*>(data), size);
    const size_t nul = input.find('\0');
    const std::string text(input.substr(0, nul));
    const std::vector<SceneOverride> overrides =
        nul == std::string_view::npos ? std::vector<SceneOverride>() : ParseOverrides(input.substr(nul + 1));

    Result<Scene> scene = ParseScene(text, "fuzz.json", overrides);
    if (!scene) {
        // Every refusal names the label, as "file: field: reason" does.
        Require(scene.error().message.starts_with("fuzz.json"), "an error names the file");
        return 0;
    }
    SetUpStages(*scene);
    return 0;
}
