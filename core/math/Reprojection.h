// Temporal reprojection (SPEC 19): a frame traces one pixel of each k x k block, chosen in a fixed Bayer order by
// the frame's number, and fills the others from the previous frame, reprojected by the depth of their block's traced
// pixel and clamped to the colours of the traced pixels around them. The definitions every backend follows;
// decisions where SPEC is silent: docs/pipeline.md, "Temporal reprojection". Scalar float, so a GLSL twin can
// follow it line by line.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/math/Camera.h"
#include "core/math/Grid.h"

namespace cb {

// The block edges a scene may ask for (march.reprojection.block).
inline constexpr uint32_t kReprojectionBlocks[] = {1, 2, 4};

// What one frame traces and where the pixels it does not trace come from.
struct ReprojectionSetup {
    uint32_t block = 1;                 // k: one pixel of each k x k block is traced
    uint32_t offsetX = 0, offsetY = 0;  // the traced pixel's place in every block this frame
    bool full = true;                   // every pixel traced: k = 1, the first frame, a camera cut
    CameraFrame previous;               // the previous frame's camera (read only when not full)
};

// The rank of cell (x, y) of the k x k Bayer matrix (k a power of two): the cell a frame of number f traces is the one
// of rank f mod k^2, so that any k^2 consecutive frames trace every pixel once and consecutive ranks lie far apart.
// k = 2: [[0, 2], [3, 1]] (rows y); each doubling nests it: B_2n(x, y) = 4 B_n(x mod n, y mod n) + B_2(x / n, y / n).
inline uint32_t BayerRank(uint32_t k, uint32_t x, uint32_t y) {
    // The coarsest bit of x and y picks B_2's rank, each finer bit pair a rank 4 times larger.
    uint32_t rank = 0, weight = 1;
    for (uint32_t n = k / 2; n >= 1; n /= 2, weight *= 4) {
        const uint32_t bx = (x / n) & 1u, by = (y / n) & 1u;
        // B_2(bx, by): (0, 0) -> 0, (1, 1) -> 1, (1, 0) -> 2, (0, 1) -> 3.
        const uint32_t b2 = bx == by ? bx : 2u + by;
        rank += b2 * weight;
    }
    return rank;
}

// This frame's setup: frame `sequence` of the run (frames drawn before it), block edge k, a camera cut at this frame
// or not, and the previous frame's camera.
inline ReprojectionSetup MakeReprojection(uint32_t k, uint32_t sequence, bool cut, const CameraFrame& previous) {
    ReprojectionSetup r;
    r.block = k;
    r.full = k <= 1 || sequence == 0 || cut;
    r.previous = previous;
    if (r.full) return r;
    const uint32_t rank = sequence % (k * k);
    for (uint32_t y = 0; y < k; ++y)
        for (uint32_t x = 0; x < k; ++x)
            if (BayerRank(k, x, y) == rank) r.offsetX = x, r.offsetY = y;
    return r;
}

// Blocks across an extent of `pixels` (the last may be partial).
inline uint32_t ReprojectionBlocks(uint32_t pixels, uint32_t k) { return (pixels + k - 1) / k; }

// The traced pixel's coordinate in block b along an axis of `pixels` pixels: b k + offset, or the axis's last pixel
// in a last block too short to hold it.
inline uint32_t TracedCoordinate(uint32_t b, uint32_t k, uint32_t offset, uint32_t pixels) {
    return std::min(b * k + offset, pixels - 1);
}

// The view depth (metres along the camera's forward axis) of a marched pixel: the ray's transmittance-weighted depth
// t = depthSum / (1 - T_view), depthSum the sum over samples of T_view (1 - tau) t_sample (each sample weighted by
// the light it lets reach the eye), in voxel edges along the unit ray, times h cos(ray, forward); a ray through
// nothing (T_view = 1) lies at the far plane.
inline float MarchViewDepth(float depthSum, float transmittance, float voxelSize, float cosForward,
                            float farPlane) {
    const float opacity = 1.0f - transmittance;
    if (!(opacity > 0.0f)) return farPlane;
    return depthSum / opacity * voxelSize * cosForward;
}

// Pixel column x's and row y's offsets on camera c's image plane at unit depth: the ray through pixel (x, y) is
// forward + u right + v up (PixelRayDirection before normalising).
inline float PixelPlaneU(const CameraFrame& c, uint32_t x) {
    return (float(x) + 0.5f - 0.5f * float(c.width)) / c.focalPx;
}
inline float PixelPlaneV(const CameraFrame& c, uint32_t y) {
    return (0.5f * float(c.height) - (float(y) + 0.5f)) / c.focalPx;
}

// Where the point at view depth z on camera c's ray through image-plane offsets (u, v) (PixelPlaneU, PixelPlaneV) lay
// in the previous camera's image: pixel coordinates (px, py) with pixel i's centre at i + 0.5 (core/math/Camera.h
// Project's convention). False where the point lies behind the previous camera or outside its image.
inline bool PreviousImagePosition(const CameraFrame& c, const CameraFrame& prev, float u, float v, float z, float& px,
                                  float& py) {
    float d[3];
    for (int i = 0; i < 3; ++i) d[i] = (c.eye[i] + z * (c.forward[i] + u * c.right[i] + v * c.upVector[i])) - prev.eye[i];
    const float right = d[0] * prev.right[0] + d[1] * prev.right[1] + d[2] * prev.right[2];
    const float up = d[0] * prev.upVector[0] + d[1] * prev.upVector[1] + d[2] * prev.upVector[2];
    const float depth = d[0] * prev.forward[0] + d[1] * prev.forward[1] + d[2] * prev.forward[2];
    if (!(depth > 0.0f)) return false;
    const float perDepth = prev.focalPx / depth;
    px = 0.5f * float(prev.width) + right * perDepth;
    py = 0.5f * float(prev.height) - up * perDepth;
    return px >= 0.0f && px <= float(prev.width) && py >= 0.0f && py <= float(prev.height);
}

// An RGB image (3 floats a pixel, row 0 at the top) read bilinearly at pixel position (px, py) (centres at i + 0.5),
// the taps clamped to the image.
inline Vec3 BilinearRgb(const float* rgb, uint32_t width, uint32_t height, float px, float py) {
    const float cx = px - 0.5f, cy = py - 0.5f;
    const float fx = std::floor(cx), fy = std::floor(cy);
    const float wx = cx - fx, wy = cy - fy;
    const int32_t ix = int32_t(fx), iy = int32_t(fy), w = int32_t(width), h = int32_t(height);
    const int32_t x0 = std::clamp(ix, 0, w - 1), x1 = std::clamp(ix + 1, 0, w - 1);
    const int32_t y0 = std::clamp(iy, 0, h - 1), y1 = std::clamp(iy + 1, 0, h - 1);
    const float* a = rgb + 3 * (size_t(x0) + size_t(width) * size_t(y0));
    const float* b = rgb + 3 * (size_t(x1) + size_t(width) * size_t(y0));
    const float* d = rgb + 3 * (size_t(x0) + size_t(width) * size_t(y1));
    const float* e = rgb + 3 * (size_t(x1) + size_t(width) * size_t(y1));
    Vec3 out;
    for (int c = 0; c < 3; ++c) {
        const float top = a[c] + wx * (b[c] - a[c]), bottom = d[c] + wx * (e[c] - d[c]);
        out[c] = top + wy * (bottom - top);
    }
    return out;
}

// An untraced pixel's colour, its ray through image-plane offsets (u, v): the previous image (`previous`, the previous
// camera's) read where the point at its block's traced view depth z lay, clamped per channel to [lo, hi] (the least
// and greatest traced colours of its block and the eight around it); where that point was not in the previous image,
// its block's traced colour.
inline Vec3 ReprojectedColor(const ReprojectionSetup& r, const CameraFrame& c, const float* previous, float u, float v,
                             float z, const Vec3& traced, const Vec3& lo, const Vec3& hi) {
    float px, py;
    if (!PreviousImagePosition(c, r.previous, u, v, z, px, py)) return traced;
    Vec3 out = BilinearRgb(previous, r.previous.width, r.previous.height, px, py);
    for (int i = 0; i < 3; ++i) out[i] = std::min(std::max(out[i], lo[i]), hi[i]);
    return out;
}

}  // namespace cb
