// Making a splat (SPEC 8): the frame every splat of one image shares, as one
// std430 block the GPU backends upload unchanged, and the per-voxel splat and
// per-pixel alpha. GLSL twin: core/math/splat.glsl (needs shading.glsl).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "core/math/Light.h"
#include "core/math/Shading.h"

namespace cb {

// The std430 block `SplatFrame` of core/math/splat.glsl, member for member (a
// scalar after a 3-vector takes its fourth lane). Members marked (backend) are
// left 0 by MakeSplatFrame (core/pipeline/SplatFrame.h) for a backend's own use.
struct alignas(16) SplatFrame {
    uint32_t grid[3];        // nx, ny, nz
    uint32_t ranksPerChunk;  // (backend: Vulkan's ranks per chunk)
    uint32_t axes[3];        // outer, middle, inner axis
    uint32_t voxelCount;
    uint32_t orderBase[3];  // where each axis's order starts in the flat order (outer, middle, inner)
    uint32_t unused0;
    uint32_t boxTile;    // the occupancy boxes: tile edge,
    uint32_t boxBand;    // band depth,
    uint32_t boxTilesX;  // tiles across,
    uint32_t boxTilesY;  // tiles down
    uint32_t width;      // the image
    uint32_t height;
    uint32_t tilesX;  // (backend: Vulkan's screen tiles across)
    uint32_t tilesY;  // (backend: and down)
    float eye[3];
    float nearPlane;
    float forward[3];
    float focalPx;
    float right[3];
    float qMin;
    float up[3];
    float opacity;
    float sun[3];     // toward the sun
    float voxelSize;  // h
    float background[3];
    float splatDiameter;
    float origin[3];
    float alpha;         // the frame's time between the two steps
    float maxPointSize;  // (backend: OpenGL's largest point size)
    float unused1;
    float unused2;
    float unused3;
    LightGpu light;  // the sun, the ambient light and the phase (core/math/Light.h)
};
static_assert(sizeof(SplatFrame) == 13 * 16 + sizeof(LightGpu), "SplatFrame is thirteen 16-byte rows and its light");
static_assert(offsetof(SplatFrame, light) % 16 == 0, "a nested struct starts a 16-byte row");

// One splat, as the std430 struct `Splat` of core/math/splat.glsl (48 bytes).
struct Splat {
    float px, py, size;  // centre in pixels (row 0 at the top), edge length in pixels
    float alphaScale;    // q_alpha * opacity
    float colour[3];     // sun * T * phase + ambient
    float pad;
    int32_t x0, x1, y0, y1;  // covered pixels, inclusive and clipped to the image (x0 > x1 when none)
};
static_assert(sizeof(Splat) == 48);

// q at the frame's time: q_prev + alpha (q_cur - q_prev).
inline float SplatQ(float qPrev, float qCur, float alpha) { return qPrev + alpha * (qCur - qPrev); }

// The splat of voxel (i, j, k) with q_alpha qa, transmittance t and the sky light's tSky (read with it on). False, and
// no splat, when qa <= q_min, the voxel centre is not beyond the near plane, or
// the centre or size in pixels is not finite (an extreme focal length). The
// covered pixels are clamped in float before the conversion to int, so a splat
// far outside the image gets an empty range (x0 > x1 or y0 > y1), never a wrap.
inline bool MakeSplat(const SplatFrame& F, uint32_t i, uint32_t j, uint32_t k, float qa, float t, float tSky,
                      Splat& s) {
    s = Splat{0, 0, 0, 0, {0, 0, 0}, 0, 0, -1, 0, -1};
    if (!(qa > F.qMin)) return false;
    const float h = F.voxelSize;
    const float cx = F.origin[0] + (float(i) + 0.5f) * h, cy = F.origin[1] + (float(j) + 0.5f) * h,
                cz = F.origin[2] + (float(k) + 0.5f) * h;
    const float dx = cx - F.eye[0], dy = cy - F.eye[1], dz = cz - F.eye[2];
    const float x = dx * F.right[0] + dy * F.right[1] + dz * F.right[2];
    const float y = dx * F.up[0] + dy * F.up[1] + dz * F.up[2];
    const float depth = dx * F.forward[0] + dy * F.forward[1] + dz * F.forward[2];
    if (!(depth > F.nearPlane)) return false;
    const float focal = F.focalPx;
    const float px = 0.5f * float(F.width) + x * focal / depth;
    const float py = 0.5f * float(F.height) - y * focal / depth;
    const float size = std::clamp(F.splatDiameter * focal / depth, 1.0f, 255.0f);
    if (!std::isfinite(px) || !std::isfinite(py) || !std::isfinite(size)) return false;
    s.px = px;
    s.py = py;
    s.size = size;
    const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float cosTheta = (F.sun[0] * dx + F.sun[1] * dy + F.sun[2] * dz) / len;
    const LightTerms terms = LightTermsOf(F.light);
    const float light = SunGain(terms, MakeSunPhases(terms, cosTheta), t);
    s.alphaScale = qa * F.opacity;
    // The sample: the voxel centre in voxel units, seen along the unit direction from the eye.
    const Vec3 at{float(i) + 0.5f, float(j) + 0.5f, float(k) + 0.5f};
    const Vec3 dir{dx / len, dy / len, dz / len};
    const float skyGain = terms.skyOn ? tSky * SkyPhase(terms, dir) : 0.0f;
    const Vec3 colour = InScattered(terms, LightSample{light, t, 1.0f, at, dir, skyGain});
    for (int c = 0; c < 3; ++c) s.colour[c] = colour[c];
    // Covered pixels: px - s/2 <= x + 0.5 < px + s/2.
    // Clamped to [0, image] and [-1, image - 1] in float, so the ints cannot overflow.
    const float half = 0.5f * s.size, imageW = float(F.width), imageH = float(F.height);
    s.x0 = int32_t(std::min(std::max(0.0f, std::ceil(s.px - half - 0.5f)), imageW));
    s.x1 = int32_t(std::max(std::min(imageW - 1.0f, std::ceil(s.px + half - 0.5f) - 1.0f), -1.0f));
    s.y0 = int32_t(std::min(std::max(0.0f, std::ceil(s.py - half - 0.5f)), imageH));
    s.y1 = int32_t(std::max(std::min(imageH - 1.0f, std::ceil(s.py + half - 0.5f) - 1.0f), -1.0f));
    return true;
}

// The splat coordinate (0 .. 1 across the splat) of the pixel whose centre is at
// pixelCentre (x + 0.5), for a splat centred at `centre` with edge `size`.
inline float SplatCoord(float pixelCentre, float centre, float size) { return (pixelCentre - centre) / size + 0.5f; }

// A pixel's alpha at splat coordinate (a, b): clamp(alphaScale kappa(a, b), 0, 1).
// Compositing is then C <- Lerp(C, colour, alpha).
inline float SplatAlpha(float alphaScale, float a, float b) {
    return std::clamp(alphaScale * SplatKernel(a, b), 0.0f, 1.0f);
}

}  // namespace cb
