// The push-constant blocks of the Vulkan shaders (impl_vk/shaders/*.comp,
// `layout(push_constant) uniform Params { ... } pc;`), each declared once as a
// member list X(type, name) that makes the C++ struct the host pushes and the
// table tests/GpuBlockLayoutTest.cpp checks member by member (name, offset,
// type) against glslang's reflection of the shader. The members are those of
// the GLSL block, in its order, with its names.
#pragma once

#include <array>
#include <cstdint>

namespace cb::vk {

// One member or entry per line, as in the GLSL blocks.
// clang-format off

using PushVec3 = std::array<float, 3>;    // GLSL vec3 (a scalar after it takes its fourth lane)
using PushFloat8 = std::array<float, 8>;  // GLSL float[8]

// Each block: its C++ name and its members (below).
#define CB_VK_PUSH_BLOCKS(X) \
    X(CaInitPush, CB_VK_CA_INIT_PUSH) \
    X(CaStepPush, CB_VK_CA_STEP_PUSH) \
    X(AdvectPush, CB_VK_ADVECT_PUSH) \
    X(RegionPush, CB_VK_REGION_PUSH) \
    X(SmoothPush, CB_VK_SMOOTH_PUSH) \
    X(DensityPush, CB_VK_DENSITY_PUSH) \
    X(NoisePush, CB_VK_NOISE_PUSH) \
    X(ShadeSlicePush, CB_VK_SHADE_SLICE_PUSH) \
    X(ShadeBlockPush, CB_VK_SHADE_BLOCK_PUSH) \
    X(ShadeResamplePush, CB_VK_SHADE_RESAMPLE_PUSH) \
    X(ShadowPush, CB_VK_SHADOW_PUSH) \
    X(SplatBoxesPush, CB_VK_SPLAT_BOXES_PUSH) \
    X(SplatChunksPush, CB_VK_SPLAT_CHUNKS_PUSH) \
    X(SplatPairsPush, CB_VK_SPLAT_PAIRS_PUSH) \
    X(SplatRangesPush, CB_VK_SPLAT_RANGES_PUSH) \
    X(SplatCompositePush, CB_VK_SPLAT_COMPOSITE_PUSH) \
    X(ScanPush, CB_VK_SCAN_PUSH) \
    X(RadixSortPush, CB_VK_RADIX_SORT_PUSH) \
    X(MarchVolumePush, CB_VK_MARCH_VOLUME_PUSH) \
    X(MarchBricksPush, CB_VK_MARCH_BRICKS_PUSH) \
    X(SkyVolumePush, CB_VK_SKY_VOLUME_PUSH)

// Every shader with a push-constant block and the block it is pushed (its file stem in impl_vk/shaders/).
#define CB_VK_PUSH_SHADERS(X) \
    X(CaInitPush, "ca_init") \
    X(CaStepPush, "ca") \
    X(AdvectPush, "advect") \
    X(RegionPush, "region") \
    X(SmoothPush, "smooth") \
    X(DensityPush, "density") \
    X(NoisePush, "noise") \
    X(ShadeSlicePush, "shade_slice") \
    X(ShadeBlockPush, "shade_block") \
    X(ShadeResamplePush, "shade_down") \
    X(ShadeResamplePush, "shade_up") \
    X(ShadowPush, "shadow") \
    X(SplatBoxesPush, "splat_boxes") \
    X(SplatChunksPush, "splat_count") \
    X(SplatChunksPush, "splat_write") \
    X(SplatPairsPush, "splat_pairs") \
    X(SplatRangesPush, "splat_ranges") \
    X(SplatCompositePush, "splat_composite") \
    X(ScanPush, "scan") \
    X(RadixSortPush, "radix_sort") \
    X(MarchVolumePush, "march_volume") \
    X(MarchBricksPush, "march_bricks") \
    X(SkyVolumePush, "sky_volume")

#define CB_VK_CA_INIT_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, words) \
    X(uint32_t, seed) \
    X(uint32_t, qHum0) \
    X(uint32_t, qAct0)
#define CB_VK_CA_STEP_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, words) \
    X(uint32_t, seed) \
    X(uint32_t, step) \
    X(uint32_t, qExt) \
    X(uint32_t, qHum) \
    X(uint32_t, qAct) \
    X(uint32_t, first) \
    X(uint32_t, end)
#define CB_VK_ADVECT_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, words) \
    X(uint32_t, first) \
    X(uint32_t, end)
#define CB_VK_REGION_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, k0) \
    X(uint32_t, first) \
    X(uint32_t, end) \
    X(uint32_t, tilesX) \
    X(uint32_t, tilesY)
// pass, first, end: the pass (x, y, z) and the share's voxels.
#define CB_VK_SMOOTH_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, words) \
    X(int32_t, radius) \
    X(float, invW) \
    X(uint32_t, pass) \
    X(uint32_t, first) \
    X(uint32_t, end)
#define CB_VK_DENSITY_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, words) \
    X(uint32_t, fromCld) \
    X(uint32_t, tile) \
    X(uint32_t, band) \
    X(uint32_t, tilesX) \
    X(uint32_t, tilesY) \
    X(uint32_t, bandCount) \
    X(uint32_t, ty0)
#define CB_VK_NOISE_PUSH(X) \
    X(PushFloat8, offsets)
#define CB_VK_SHADE_SLICE_PUSH(X) \
    X(uint32_t, nu) \
    X(uint32_t, nv) \
    X(uint32_t, strideU) \
    X(uint32_t, strideV) \
    X(uint32_t, sliceBase) \
    X(uint32_t, prevBase) \
    X(int32_t, u0) \
    X(int32_t, v0) \
    X(float, fu) \
    X(float, fv) \
    X(uint32_t, first) \
    X(uint32_t, beer) \
    X(float, depthPerQ) \
    X(float, thesisAr) \
    X(float, scatterGain) \
    X(uint32_t, storage)
#define CB_VK_SHADE_BLOCK_PUSH(X) \
    X(uint32_t, nu) \
    X(uint32_t, nv) \
    X(uint32_t, strideU) \
    X(uint32_t, strideV) \
    X(uint32_t, strideW) \
    X(uint32_t, nw) \
    X(uint32_t, sunAbove) \
    X(uint32_t, begin) \
    X(uint32_t, end) \
    X(int32_t, u0) \
    X(int32_t, v0) \
    X(float, fu) \
    X(float, fv) \
    X(uint32_t, beer) \
    X(float, depthPerQ) \
    X(float, thesisAr) \
    X(float, scatterGain) \
    X(uint32_t, storage)
// shade_down and shade_up: the grid (nx, ny, nz), the shaded cells (cx, cy, cz) and the resolution f.
#define CB_VK_SHADE_RESAMPLE_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, cx) \
    X(uint32_t, cy) \
    X(uint32_t, cz) \
    X(uint32_t, f)
// form: ShadowForm; noSun: 1 when G = 1.
#define CB_VK_SHADOW_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(int32_t, bx) \
    X(int32_t, by) \
    X(float, fx) \
    X(float, fy) \
    X(uint32_t, form) \
    X(float, opticalDepthPerD) \
    X(float, kappa) \
    X(uint32_t, noSun) \
    X(float, coverage) \
    X(float, densityFactor)
#define CB_VK_SPLAT_BOXES_PUSH(X) \
    X(uint32_t, words)
#define CB_VK_SPLAT_CHUNKS_PUSH(X) \
    X(uint32_t, chunks) \
    X(uint32_t, tileSize)
#define CB_VK_SPLAT_PAIRS_PUSH(X) \
    X(uint32_t, splatCount) \
    X(uint32_t, tilesX) \
    X(uint32_t, tileSize)
#define CB_VK_SPLAT_RANGES_PUSH(X) \
    X(uint32_t, pairs) \
    X(uint32_t, tiles)
#define CB_VK_SPLAT_COMPOSITE_PUSH(X) \
    X(uint32_t, width) \
    X(uint32_t, height) \
    X(uint32_t, tilesX) \
    X(uint32_t, tileSize) \
    X(PushVec3, background) \
    X(uint32_t, ground)
#define CB_VK_SCAN_PUSH(X) \
    X(uint32_t, n) \
    X(uint32_t, mode)
#define CB_VK_RADIX_SORT_PUSH(X) \
    X(uint32_t, n) \
    X(uint32_t, shift) \
    X(uint32_t, block) \
    X(uint32_t, blocks) \
    X(uint32_t, mode)
#define CB_VK_MARCH_VOLUME_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, hasT) \
    X(float, alpha) \
    X(uint32_t, wrap)
#define CB_VK_MARCH_BRICKS_PUSH(X) \
    X(uint32_t, px) \
    X(uint32_t, py) \
    X(uint32_t, pz) \
    X(uint32_t, brick) \
    X(uint32_t, bx) \
    X(uint32_t, by) \
    X(uint32_t, bz) \
    X(uint32_t, qStride)
// The grid (nx, ny, nz) and wrap: 1 with tiling.
#define CB_VK_SKY_VOLUME_PUSH(X) \
    X(uint32_t, nx) \
    X(uint32_t, ny) \
    X(uint32_t, nz) \
    X(uint32_t, wrap)

// clang-format on

#define CB_VK_PUSH_MEMBER(type, name) type name;
#define CB_VK_PUSH_STRUCT(Name, MEMBERS) \
    struct Name {                        \
        MEMBERS(CB_VK_PUSH_MEMBER)       \
    };
CB_VK_PUSH_BLOCKS(CB_VK_PUSH_STRUCT)
#undef CB_VK_PUSH_STRUCT
#undef CB_VK_PUSH_MEMBER

}  // namespace cb::vk
