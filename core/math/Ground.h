// The ground plane in the frame (docs/pipeline.md, "The
// ground in the frame"): the plane z = origin_z (SPEC 7) under the clouds, a
// Lambertian surface of the scene's albedo lit by the sun through the ground
// shadow G (Wang, Ji and Zhang, eq. 19) and by the ambient light. Both renderers take it
// as the pixel's background: where the pixel's ray meets the plane between the
// near and far planes, background = albedo (sunRadiance max(s_z, 0) G(p) +
// ambient); elsewhere the flat background. The clouds are composited over it
// as over the flat one.
//
// Voxel units as in core/math/March.h: the ground is z = 0, ground cell (i, j) of
// G has its centre at (i + 0.5, j + 0.5). Scalar float code that
// core/math/ground.glsl twins line by line.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "core/math/Camera.h"
#include "core/math/March.h"
#include "core/math/Shading.h"

namespace cb {

// The scene's ground (`render.ground`); off: every pixel gets the flat background.
struct GroundParams {
    bool on = false;
    Vec3 albedo{0, 0, 0};  // linear RGB
};

// The light the ground receives, and the flat background where no ground is seen.
struct GroundLight {
    Vec3 albedo{}, sunRadiance{}, ambient{}, background{};
    float sunZ = 1;  // s_z of the unit vector toward the sun
};

// Where the ray o + t d (voxel units, d unit) meets the plane z = 0 with t in
// [tNear, tFar]: true and the point's (x, y). A ray that does not point down
// (d_z >= 0) never meets it.
inline bool GroundHit(const Vec3& o, const Vec3& d, float tNear, float tFar, float& x, float& y) {
    if (!(d[2] < 0.0f)) return false;
    const float t = (0.0f - o[2]) / d[2];
    if (!(t >= tNear && t <= tFar)) return false;
    x = o[0] + d[0] * t;
    y = o[1] + d[1] * t;
    return true;
}

// G at the ground point (x, y): bilinear between the cell centres, the taps
// clamped to the edge cells inside the grid's footprint [0, nx] x [0, ny], and
// 1 outside it (no cloud above). fetch(i, j) returns G of cell (i, j).
template <class Fetch>
float GroundShadowAt(float x, float y, uint32_t nx, uint32_t ny, Fetch&& fetch) {
    if (!(x >= 0.0f && x <= float(nx) && y >= 0.0f && y <= float(ny))) return 1.0f;
    const float cx = std::clamp(x - 0.5f, 0.0f, float(nx - 1));
    const float cy = std::clamp(y - 0.5f, 0.0f, float(ny - 1));
    const uint32_t i0 = uint32_t(cx), j0 = uint32_t(cy);  // cx, cy >= 0: the floor
    const uint32_t i1 = std::min(i0 + 1, nx - 1), j1 = std::min(j0 + 1, ny - 1);
    return Bilinear(fetch(i0, j0), fetch(i1, j0), fetch(i0, j1), fetch(i1, j1), cx - float(i0), cy - float(j0));
}

// One channel of the lit ground: albedo (sunRadiance max(s_z, 0) G + ambient),
// evaluated in this order (Wang eq. 19: the shadow factor scales the sun's term).
inline float GroundChannel(float albedo, float sunRadiance, float sunZ, float ambient, float g) {
    return albedo * (sunRadiance * std::max(sunZ, 0.0f) * g + ambient);
}

// The background of pixel (x, y) of camera c: the lit ground where the
// pixel's ray (core/math/March.h's, from eyeVoxel = (eye - origin) / h) meets it
// between the near and far planes, else the flat background. G is the
// canonical (nx, ny) array of the shadow stage.
inline Vec3 GroundBackground(const CameraFrame& c, const Vec3& eyeVoxel, float voxelSize, const GroundLight& light,
                             const float* G, uint32_t nx, uint32_t ny, uint32_t x, uint32_t y) {
    const PixelDirection p = PixelRayDirection(c, x, y);
    const float perDepth = 1.0f / (voxelSize * p.cosForward);
    const float tNear = c.nearPlane * perDepth, tFar = c.farPlane * perDepth;
    float gx = 0, gy = 0;
    if (!GroundHit(eyeVoxel, p.dir, tNear, tFar, gx, gy)) return light.background;
    const float g = GroundShadowAt(gx, gy, nx, ny, [&](uint32_t i, uint32_t j) { return G[i + size_t(nx) * j]; });
    return {GroundChannel(light.albedo[0], light.sunRadiance[0], light.sunZ, light.ambient[0], g),
            GroundChannel(light.albedo[1], light.sunRadiance[1], light.sunZ, light.ambient[1], g),
            GroundChannel(light.albedo[2], light.sunRadiance[2], light.sunZ, light.ambient[2], g)};
}

// The eye in voxel units, as MakePixelRay computes it.
inline Vec3 GroundEyeVoxel(const CameraFrame& c, const std::array<float, 3>& origin, float voxelSize) {
    return {(c.eye[0] - origin[0]) / voxelSize, (c.eye[1] - origin[1]) / voxelSize, (c.eye[2] - origin[2]) / voxelSize};
}

// The constants of GroundBackground on the GPU backends, one block that
// std140 and std430 lay out alike (a scalar after a vec3 takes its fourth
// lane); core/math/ground.glsl's GroundGpu twins it member for member.
struct alignas(16) GroundGpu {
    std::array<float, 3> eye;  // the eye in voxel units
    float focalPx;
    std::array<float, 3> forward;
    float nearPlane;  // metres
    std::array<float, 3> right;
    float farPlane;  // metres
    std::array<float, 3> up;
    float voxelSize;              // h, metres
    std::array<float, 3> albedo;  // rgb
    float sunZ;                   // s_z
    std::array<float, 3> sunRadiance;
    float unused0;
    std::array<float, 3> ambient;
    float unused1;
    std::array<float, 3> background;  // the flat background
    float unused2;
    uint32_t gridX;  // nx of G
    uint32_t gridY;  // ny of G
    uint32_t width;  // the image
    uint32_t height;
};
static_assert(sizeof(GroundGpu) == 9 * 16, "GroundGpu is nine 16-byte rows");

inline GroundGpu MakeGroundGpu(const CameraFrame& c, const std::array<float, 3>& origin, float voxelSize,
                               const GroundLight& light, uint32_t nx, uint32_t ny) {
    GroundGpu g{};
    SetCameraMembers(g, c, GroundEyeVoxel(c, origin, voxelSize), voxelSize);
    g.albedo = light.albedo;
    g.sunZ = light.sunZ;
    g.sunRadiance = light.sunRadiance;
    g.ambient = light.ambient;
    g.background = light.background;
    g.gridX = nx;
    g.gridY = ny;
    return g;
}

}  // namespace cb
