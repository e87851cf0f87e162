// Every GPU pass at the extents where a dispatch or a viewport goes wrong: one
// table, one row per pass and backend with its workgroup (vk: local_size of its
// .comp; gl: the tile or word that splits its viewport), the extent it
// dispatches or draws over as a function of the case, and the sizes tried, which
// put that extent at k*W - 1, k*W and k*W + 1 (the test checks the table says
// so). Each size runs the stage on the backend and on the CPU and compares them
// by the stage's rule (GpuExtentsRunners.cpp, GpuExtentsRender.cpp), after a
// larger call on the same backend, so that memory a pass misses holds stale
// values. gl's fragment passes have no workgroup: their viewports are tried at 1
// and at 63, 64 and 65 (llvmpipe rasterises in 64-pixel tiles), and where a
// texture packs 32 voxels a texel, at 31, 32 and 33. docs/testing.md, "GPU pass
// extents", is this table in prose.
#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <string>
#include <vector>

#include "tests/BackendTestUtil.h"
#include "tests/GpuExtents.h"

namespace cb::extents {
namespace {

// The extent of one axis a pass dispatches over (or draws), from a case.
using ExtentOf = std::function<uint32_t(const ExtentCase&)>;

struct ExtentRow {
    const char* name;     // test name: the pass (and the stage where a pass serves two)
    const char* backend;  // "vk" or "gl"
    Stage stage;
    uint32_t group;       // the workgroup or tile W the extent is measured against
    const char* formula;  // the extent, as docs/testing.md writes it
    std::vector<ExtentOf> axes;  // each axis's extent (each must sit at k W - 1, k W or k W + 1)
    std::vector<ExtentCase> cases;
    bool one = false;  // gl: an extent of 1 is tried too
};

uint32_t Voxels(const ExtentCase& c) { return uint32_t(c.grid.Count()); }
uint32_t Nx(const ExtentCase& c) { return c.grid.nx; }
uint32_t Ny(const ExtentCase& c) { return c.grid.ny; }
uint32_t Width(const ExtentCase& c) { return c.width; }
uint32_t Height(const ExtentCase& c) { return c.height; }
uint32_t PaddedNx(const ExtentCase& c) { return c.grid.nx + 2; }
uint32_t PaddedNy(const ExtentCase& c) { return c.grid.ny + 2; }
uint32_t Words(const ExtentCase& c) { return CeilDiv(c.grid.nx, 32u) * c.grid.ny * c.grid.nz; }
uint32_t Columns(const ExtentCase& c) { return c.grid.nx * c.grid.ny; }
uint32_t HalfCells(const ExtentCase& c) {
    return CeilDiv(c.grid.nx, 2u) * CeilDiv(c.grid.ny, 2u) * CeilDiv(c.grid.nz, 2u);
}
uint32_t HalfNx(const ExtentCase& c) { return CeilDiv(c.grid.nx, 2u); }
uint32_t HalfNy(const ExtentCase& c) { return CeilDiv(c.grid.ny, 2u); }
uint32_t Chunks32(const ExtentCase& c) { return CeilDiv(Voxels(c), 32u); }
uint32_t BoxWords(const ExtentCase& c) { return CeilDiv(HalfNx(c) * HalfNy(c) * c.grid.nz, 4u); }
uint32_t ScreenTilesPlusOne(const ExtentCase& c) { return CeilDiv(c.width, 8u) * CeilDiv(c.height, 8u) + 1; }

ExtentCase G(uint32_t nx, uint32_t ny, uint32_t nz, uint32_t option = 0) { return {{nx, ny, nz}, 16, 12, option}; }
ExtentCase I(uint32_t w, uint32_t h, uint32_t option = 0) { return {{6, 5, 4}, w, h, option}; }

// Flattened volumes of 63, 64, 65 and 128 voxels; planes of 63, 64, 65 columns (nz slices).
std::vector<ExtentCase> FlatVolumes(uint32_t option = 0) {
    return {G(7, 3, 3, option), G(4, 4, 4, option), G(13, 5, 1, option), G(16, 8, 1, option)};
}
std::vector<ExtentCase> FlatPlanes(uint32_t nz, uint32_t option = 0) {
    return {G(9, 7, nz, option), G(8, 8, nz, option), G(13, 5, nz, option)};
}
// A row of 31, 32, 33 voxels: one packed 32-bit word ends short, exactly, or one voxel into the next.
std::vector<ExtentCase> WordRows(uint32_t option = 0) {
    return {G(31, 5, 3, option), G(32, 5, 3, option), G(33, 5, 3, option)};
}
// gl: viewports of 1 x 1 and of 63, 64, 65 in x and y (llvmpipe's 64-pixel tiles).
std::vector<ExtentCase> GlViewports(uint32_t option = 0) {
    return {G(1, 1, 3, option), G(63, 65, 2, option), G(64, 64, 2, option), G(65, 63, 2, option)};
}
std::vector<ExtentCase> Images8(uint32_t option = 0) {
    return {I(7, 9, option), I(8, 8, option), I(9, 7, option), I(17, 15, option), I(16, 16, option)};
}
std::vector<ExtentCase> GlImages(uint32_t option = 0) {
    return {I(1, 1, option), I(63, 65, option), I(64, 64, option), I(65, 63, option)};
}
// The padded volume (nx + 2) x (ny + 2): 63, 64, 65 columns (and 128).
std::vector<ExtentCase> PaddedColumns(uint32_t option) {
    return {G(61, 3, 3, option), G(62, 3, 3, option), G(63, 3, 3, option), G(126, 2, 2, option)};
}
std::vector<ExtentCase> GlPadded(uint32_t option) {
    return {G(61, 63, 2, option), G(62, 62, 2, option), G(63, 61, 2, option)};
}

const std::vector<ExtentRow>& Table() {
    static const std::vector<ExtentRow> rows = {
        // Vulkan: one row per vkCmdDispatch, W its shader's local_size.
        {"noise", "vk", Stage::Noise, 64, "nx ny nz", {Voxels}, FlatVolumes()},
        {"region", "vk", Stage::Region, 64, "nx ny nz", {Voxels}, FlatVolumes()},
        {"region_tile_lists", "vk", Stage::Region, 16, "nx, ny (host tile lists)", {Nx, Ny},
         {G(15, 15, 2), G(16, 16, 2), G(17, 17, 2)}},
        {"ca_init_and_ca", "vk", Stage::Ca, 64, "ceil(nx/32) ny nz", {Words},
         {G(20, 7, 9), G(20, 8, 8), G(20, 5, 13), G(40, 8, 4)}},
        {"advect", "vk", Stage::Ca, 64, "ceil(nx/32) ny nz (wind)", {Words},
         {G(20, 7, 9, 1), G(20, 8, 8, 1), G(20, 5, 13, 1), G(40, 8, 4, 1)}},
        {"ca_words", "vk", Stage::Ca, 32, "nx (bits a word)", {Nx}, WordRows(1)},
        {"smooth", "vk", Stage::Smooth, 64, "nx ny nz, each of 3 passes", {Voxels}, FlatVolumes(2)},
        {"smooth_words", "vk", Stage::Smooth, 32, "nx (bits a word)", {Nx}, WordRows(2)},
        {"density", "vk", Stage::Density, 8, "nx, ny (tiles; one workgroup each)", {Nx, Ny},
         {G(15, 15, 5, 8), G(16, 16, 5, 8), G(17, 17, 5, 8)}},
        {"shade_down", "vk", Stage::Shade, 64, "ceil(nx/2) ceil(ny/2) ceil(nz/2) (f = 2)", {HalfCells},
         {G(14, 6, 6, 2), G(8, 8, 8, 2), G(26, 10, 2, 2)}},
        {"shade_slice", "vk", Stage::Shade, 64, "n_u n_v = nx ny (sun overhead, f = 1)", {Columns}, FlatPlanes(3, 1)},
        {"shade_up", "vk", Stage::Shade, 64, "nx ny nz (f = 2)", {Voxels}, FlatVolumes(2)},
        {"shade_block", "vk", Stage::Shade, 32, "n_u, n_v = nx, ny (32 x 32 tiles)", {Nx, Ny},
         {G(31, 31, 3, 101), G(32, 32, 3, 101), G(33, 33, 3, 101)}},
        {"shadow", "vk", Stage::Shadow, 64, "nx ny", {Columns}, FlatPlanes(2)},
        {"splat_count_and_write", "vk", Stage::RenderSplat, 64, "ceil(nx ny nz / 32) chunks (32 ranks)", {Chunks32},
         {G(18, 14, 8, 32), G(16, 16, 8, 32), G(20, 13, 8, 32)}},
        {"splat_pairs", "vk", Stage::RenderSplat, 64, "splats = nx ny nz", {Voxels}, FlatVolumes()},
        {"splat_boxes", "vk", Stage::RenderSplat, 64, "ceil(ceil(nx/2) ceil(ny/2) nz / 4) (tile 2, band 1)",
         {BoxWords}, {G(12, 12, 7, 1000), G(16, 16, 4, 1000), G(10, 26, 4, 1000)}},
        {"splat_ranges", "vk", Stage::RenderSplat, 64, "ceil(W/8) ceil(H/8) + 1", {ScreenTilesPlusOne},
         {I(248, 16), I(72, 56), I(64, 64)}},
        {"splat_composite", "vk", Stage::RenderSplat, 8, "W, H", {Width, Height}, Images8()},
        {"march_volume_render_march", "vk", Stage::RenderMarch, 64, "nx + 2", {PaddedNx}, PaddedColumns(8)},
        {"march_bricks", "vk", Stage::RenderMarch, 64, "ceil(nx/B) (B = 1)", {Nx},
         {G(63, 3, 3, 1), G(64, 3, 3, 1), G(65, 3, 3, 1)}},
        {"render_march", "vk", Stage::RenderMarch, 8, "W, H", {Width, Height}, Images8(8)},
        {"march_volume_render_layers", "vk", Stage::RenderLayers, 64, "nx + 2", {PaddedNx}, PaddedColumns(0)},
        {"march_volume_render_layers_tiled", "vk", Stage::RenderLayers, 64, "nx + 2 (tiling)", {PaddedNx},
         PaddedColumns(1)},
        {"render_layers", "vk", Stage::RenderLayers, 8, "W, H", {Width, Height}, Images8(1)},
        {"render_layers_lod0", "vk", Stage::RenderLayers, 8, "W, H (billboards)", {Width, Height}, Images8(2)},
        // OpenGL: fragment passes; the viewport's extent in each axis.
        {"noise", "gl", Stage::Noise, 64, "nx, ny", {Nx, Ny}, GlViewports(), true},
        {"region", "gl", Stage::Region, 64, "nx, ny", {Nx, Ny}, GlViewports(), true},
        {"ca", "gl", Stage::Ca, 64, "nx, ny (rules)", {Nx, Ny}, GlViewports(1), true},
        {"ca_words", "gl", Stage::Ca, 32, "nx (ceil(nx/32) texels: pack, unpack)", {Nx}, WordRows(1)},
        {"smooth", "gl", Stage::Smooth, 64, "nx, ny", {Nx, Ny}, GlViewports(2), true},
        {"smooth_words", "gl", Stage::Smooth, 32, "nx (ceil(nx/32) texels of cld)", {Nx}, WordRows(2)},
        {"density", "gl", Stage::Density, 64, "nx, ny (D, cover)", {Nx, Ny}, GlViewports(8), true},
        {"density_tiles", "gl", Stage::Density, 8, "nx, ny (tiles: occupancy)", {Nx, Ny},
         {G(15, 15, 5, 8), G(16, 16, 5, 8), G(17, 17, 5, 8)}},
        {"shade_slice", "gl", Stage::Shade, 64, "n_u, n_v = nx, ny (f = 1)", {Nx, Ny}, GlViewports(1), true},
        {"shade_down", "gl", Stage::Shade, 64, "ceil(nx/2), ceil(ny/2) (f = 2)", {HalfNx, HalfNy},
         {G(1, 1, 2, 2), G(125, 129, 2, 2), G(128, 128, 2, 2), G(129, 125, 2, 2)}, true},
        {"shadow", "gl", Stage::Shadow, 64, "nx, ny", {Nx, Ny}, GlViewports(), true},
        {"splat", "gl", Stage::RenderSplat, 64, "W, H (+ 2 guard)", {Width, Height}, GlImages(), true},
        {"march_volume_render_march", "gl", Stage::RenderMarch, 64, "nx + 2, ny + 2", {PaddedNx, PaddedNy},
         GlPadded(8)},
        {"march_bricks", "gl", Stage::RenderMarch, 64, "ceil(nx/B), ceil(ny/B) (B = 1)", {Nx, Ny},
         {G(1, 1, 2, 1), G(63, 65, 2, 1), G(64, 64, 2, 1), G(65, 63, 2, 1)}, true},
        {"render_march", "gl", Stage::RenderMarch, 64, "W, H", {Width, Height}, GlImages(8), true},
        {"march_volume_render_layers", "gl", Stage::RenderLayers, 64, "nx + 2, ny + 2 (tiling)",
         {PaddedNx, PaddedNy}, GlPadded(1)},
        {"render_layers", "gl", Stage::RenderLayers, 64, "W, H", {Width, Height}, GlImages(0), true},
        {"render_layers_lod0", "gl", Stage::RenderLayers, 64, "W, H (billboards)", {Width, Height}, GlImages(2), true},
    };
    return rows;
}

class GpuExtents : public ::testing::TestWithParam<size_t> {};

// Test one pass at its extents: the table puts each axis's extent at k W - 1, k W and k W + 1 (each at least once),
// and at every size the backend equals the CPU by the stage's rule, after a larger call on the same backend.
TEST_P(GpuExtents, PassMatchesTheCpuAtItsEdges) {
    const ExtentRow& row = Table()[GetParam()];
    for (size_t a = 0; a < row.axes.size(); ++a) {
        std::set<uint32_t> residues;
        for (const ExtentCase& c : row.cases) {
            const uint32_t extent = row.axes[a](c), r = extent % row.group;
            if (row.one && extent == 1) continue;
            EXPECT_TRUE(r == 0 || r == 1 || r == row.group - 1)
                << "the table's case " << Describe(c) << " puts " << row.formula << " at " << extent
                << ", not next to a multiple of " << row.group;
            residues.insert(r);
        }
        EXPECT_TRUE(residues.count(0) && residues.count(1) && residues.count(row.group - 1))
            << row.formula << ": the cases miss one of k W - 1, k W, k W + 1";
    }
    auto backend = test::MakeTestBackend(row.backend);
    if (!backend) GTEST_SKIP() << "unsupported here: " << backend.error().message;
    ASSERT_TRUE((*backend)->Supports(row.stage)) << row.backend << " lacks " << StageName(row.stage);
    for (const ExtentCase& c : row.cases) {
        RunExtentCase(row.stage, **backend, c);
        if (HasFatalFailure()) return;
    }
    test::ExpectNoValidationMessages(backend->get());
}

// Test that the table has a row for every stage on each GPU backend: a pass added without its extent cases fails
// here only if its stage has none, so the rule in docs/testing.md asks for a row per pass.
TEST(GpuExtentsTable, EveryStageHasRowsOnBothGpuBackends) {
    for (const char* backend : {"vk", "gl"})
        for (Stage stage : {Stage::Noise, Stage::Region, Stage::Ca, Stage::Smooth, Stage::Density, Stage::Shade,
                            Stage::Shadow, Stage::RenderSplat, Stage::RenderMarch, Stage::RenderLayers}) {
            bool found = false;
            for (const ExtentRow& row : Table()) found |= row.stage == stage && std::string(row.backend) == backend;
            EXPECT_TRUE(found) << backend << " has no extent row for " << StageName(stage);
        }
}

std::vector<size_t> RowIndices() {
    std::vector<size_t> v(Table().size());
    for (size_t i = 0; i < v.size(); ++i) v[i] = i;
    return v;
}

INSTANTIATE_TEST_SUITE_P(Passes, GpuExtents, ::testing::ValuesIn(RowIndices()), [](const auto& info) {
    const ExtentRow& row = Table()[info.param];
    return std::string(row.backend) + "_" + row.name;
});

}  // namespace
}  // namespace cb::extents
