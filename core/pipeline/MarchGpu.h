// The constants of stage `render_march` on the GPU backends, as one block of
// 16-byte rows that both std140 (GL uniform block) and std430 (Vulkan storage
// or uniform buffer) lay out the same way. core/math/march.glsl declares the
// twin struct `MarchGpu`; the field order and the flag bits below must match.
//
// Everything the CPU computes once per call (the eye in voxel units, sigma h,
// the point light in voxel units) is computed here by the same code
// (core/math/March.h, MakeMarchParams in core/stages/render_march/), so the GPU
// starts from the CPU's floats.
#pragma once

#include <array>
#include <cstdint>

#include "core/pipeline/Backend.h"

namespace cb {

// MarchGpu.flags.x bits.
enum MarchGpuFlag : uint32_t {
    kMarchGpuAdaptive = 1u << 0,
    kMarchGpuJitter = 1u << 1,
    kMarchGpuPowder = 1u << 2,
    kMarchGpuPointLight = 1u << 3,
    kMarchGpuSkipping = 1u << 4,
    kMarchGpuLightMarch = 1u << 5,  // the sun's light from a light march; else shade's T
    kMarchGpuGround = 1u << 6,      // the ground plane (core/math/Ground.h) is the background, per pixel
};

struct MarchGpu {
    std::array<float, 4> eye;            // xyz: the eye in voxel units ((eye - origin) / h); w: focalPx
    std::array<float, 4> forward;        // xyz; w: near plane (metres)
    std::array<float, 4> right;          // xyz; w: far plane (metres)
    std::array<float, 4> up;             // xyz; w: h, the voxel size (metres)
    std::array<float, 4> size;           // xyz: the box (nx, ny, nz); w: sigma h
    std::array<float, 4> stepping;       // step Delta_0, kappa, adaptive start t_a, epsilon
    std::array<float, 4> sun;            // xyz: unit, toward the sun; w: the phase's g
    std::array<float, 4> sunRadiance;    // rgb; w: the powder's c
    std::array<float, 4> ambient;        // rgb; w: the Mie table's index per radian
    std::array<float, 4> background;     // rgb; w: unused
    std::array<float, 4> pointPosition;  // xyz: voxel units; w: r0^2 (metres^2)
    std::array<float, 4> pointRadiance;  // rgb: colour * intensity; w: unused
    std::array<uint32_t, 4> image;       // width, height, seed, frame
    std::array<uint32_t, 4> flags;       // MarchGpuFlag bits, PhaseKind, light steps n_l, brick edge B
    std::array<uint32_t, 4> strides;     // padded strides px = nx + 2, px * (ny + 2); Mie table count; unused
    std::array<uint32_t, 4> bricks;      // bricks along x, y, z (ceil(n / B)); unused
};
static_assert(sizeof(MarchGpu) == 16 * 16, "MarchGpu is sixteen 16-byte rows");

// The block for one call on a grid of extent e. The Mie table's values are
// bound separately (kMieCloudTable, read by the index of march.glsl).
MarchGpu MakeMarchGpu(const MarchParams& params, const Extent3& e);

// Bricks along each axis for the skip structure: ceil(n / B), B >= 1.
std::array<uint32_t, 3> MarchBrickCounts(const Extent3& e, uint32_t brick);

}  // namespace cb
