// The constants of stage `render_layers` on the GPU backends, as one block of
// 16-byte rows that std140 (GL uniform block) and std430 (Vulkan storage
// buffer) lay out the same way. core/math/layers.glsl declares the twin struct
// `LayersGpu`; the field order and the flag bits below must match. The floats
// are the CPU's (MakeLayersParams), so every backend starts from the same ones.
#pragma once

#include <array>
#include <cstdint>

#include "core/pipeline/Backend.h"

namespace cb {

// LayersGpu.image.w bits.
enum LayersGpuFlag : uint32_t {
    kLayersGpuTiling = 1u << 0,  // the volume repeats in x and y
    kLayersGpuWang = 1u << 1,    // wang opacity (eq. 16 with the modulation map)
};

struct LayersGpu {
    std::array<float, 4> eye;          // xyz: the eye in voxel units; w: focalPx
    std::array<float, 4> forward;      // xyz; w: near plane (metres)
    std::array<float, 4> right;        // xyz; w: far plane (metres)
    std::array<float, 4> up;           // xyz; w: h, the voxel size (metres)
    std::array<float, 4> size;         // xyz: (nx, ny, nz); w: sigma h
    std::array<float, 4> invSize;      // xyz: 1 / size; w: the spacing nz / N
    std::array<float, 4> sun;          // xyz: unit, toward the sun; w: the phase's g
    std::array<float, 4> sunRadiance;  // rgb; w: extent^2 (voxel edges^2)
    std::array<float, 4> ambient;      // rgb; w: the Mie table's index per radian
    std::array<float, 4> background;   // rgb; w: l_max (voxel edges)
    std::array<uint32_t, 4> image;     // width, height, N, LayersGpuFlag bits
    std::array<uint32_t, 4> phase;     // PhaseKind, the Mie table's count, padded strides px, px * py
    std::array<float, 4> drift;        // xy: the wind's drift (voxel units); z: coverage C; w: density D_w
    std::array<float, 4> light;        // x: T's factor (LayersSetup::lightScale); y: fadeInv2; zw: unused
};
static_assert(sizeof(LayersGpu) == 14 * 16, "LayersGpu is fourteen 16-byte rows");

LayersGpu MakeLayersGpu(const LayersParams& params);

// The layers in drawing order, back to front for every pixel: decreasing
// |z_i - z_eye| (SPEC 15), ties by lower index. OpenGL's instance n draws layer order[n].
std::vector<uint32_t> LayersDrawOrder(const LayersSetup& setup);

}  // namespace cb
