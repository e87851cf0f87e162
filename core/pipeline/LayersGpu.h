// The constants of stage `render_layers` on the GPU backends, as one block of
// named members that std140 (GL uniform block) and std430 (Vulkan storage
// buffer) lay out the same way. core/math/layers.glsl declares the twin struct
// `LayersGpu`; the member order and the flag bits below must match. The floats
// are the CPU's (MakeLayersParams), so every backend starts from the same ones.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "core/math/Light.h"
#include "core/pipeline/Backend.h"

namespace cb {

// LayersGpu.flags bits.
enum LayersGpuFlag : uint32_t {
    kLayersGpuTiling = 1u << 0,  // the volume repeats in x and y
    kLayersGpuWang = 1u << 1,    // wang opacity (eq. 16 with the modulation map)
};

// Member for member layers.glsl's LayersGpu (a scalar after a vec3 takes its fourth lane in std140 and std430).
struct alignas(16) LayersGpu {
    std::array<float, 3> eye;  // the eye in voxel units
    float focalPx;
    std::array<float, 3> forward;
    float nearPlane;  // metres
    std::array<float, 3> right;
    float farPlane;  // metres
    std::array<float, 3> up;
    float voxelSize;            // h, metres
    std::array<float, 3> size;  // (nx, ny, nz)
    float sigmaH;
    std::array<float, 3> invSize;     // 1 / size
    float spacing;                    // nz / N
    std::array<float, 3> sun;         // unit, toward the sun
    float outer2;                     // extent^2 (voxel edges^2)
    std::array<float, 3> background;  // rgb
    float maxLength;                  // l_max (voxel edges)
    uint32_t width;
    uint32_t height;
    uint32_t count;    // N layers
    uint32_t flags;    // LayersGpuFlag bits
    uint32_t strideY;  // padded strides: px = nx + 2
    uint32_t strideZ;  // px * (ny + 2)
    float lightScale;  // T's factor (LayersSetup::lightScale)
    float fadeInv2;
    std::array<float, 2> drift;  // the wind's drift (voxel units)
    float coverage;              // C (wang)
    float density;               // D_w (wang)
    float inner2;                // r0^2 (voxel edges^2): LOD0's radius squared; 0: no billboards
    float halfWidth;             // W_p / 2 (voxel edges)
    float halfHeight;            // H_p / 2
    float billboardLength;       // a billboard fragment's path times cos(ray, forward) (beer)
    uint32_t billboardCount;     // the billboards' buffer (LayersBillboard, in drawing order)
    LightGpu light;              // the sun, the ambient light and the phase (core/math/Light.h)
};
static_assert(sizeof(LayersGpu) == 13 * 16 + sizeof(LightGpu), "LayersGpu is thirteen 16-byte rows and its light");
static_assert(offsetof(LayersGpu, light) % 16 == 0, "a nested struct starts a 16-byte row");

// billboardCount: the length of the call's billboard list (MakeLayersBillboards).
LayersGpu MakeLayersGpu(const LayersParams& params, uint32_t billboardCount = 0);
static_assert(sizeof(LayersBillboard) == 16, "a billboard is one vec4 in std430");

// The layers in drawing order, back to front for every pixel: decreasing
// |z_i - z_eye| (SPEC 15), ties by lower index. OpenGL's instance n draws layer order[n].
std::vector<uint32_t> LayersDrawOrder(const LayersSetup& setup);

}  // namespace cb
