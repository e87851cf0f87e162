// Cameras and the shared back-to-front splat order (SPEC 8, docs/contract.md).
// Everything here runs on the host, once per frame, and is handed to every
// backend, so all backends project and sort the same way.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math/Grid.h"
#include "core/math/Shading.h"

namespace cb {

// A pose on a camera's track at one frame of the run (the frames drawn before it).
struct CameraKeyframe {
    uint32_t frame = 0;
    std::array<double, 3> eye{0, 0, 0}, target{1, 0, 0};
    bool cut = false;  // a camera cut: the pose jumps here from the previous keyframe's (no motion between them)
};

struct CameraSettings {
    std::string name = "view";
    std::array<double, 3> eye{0, 0, 0};     // world, metres
    std::array<double, 3> target{1, 0, 0};  // world, metres
    std::array<double, 3> up{0, 0, 1};
    double fovDeg = 60;  // vertical field of view
    double nearPlane = 1, farPlane = 100000;
    // Keyframes by increasing frame, or none for a fixed camera. Between two keyframes the eye and the target move
    // linearly (in double), unless the later one is a cut: then the earlier pose holds until the cut's frame. Before
    // the first keyframe and after the last, their poses hold.
    std::vector<CameraKeyframe> track;

    // This camera at frame `frame` of the run: eye and target from the track; itself without one.
    CameraSettings At(uint32_t frame) const;
    // Whether frame `frame` starts at a keyframe marked as a cut.
    bool CutAt(uint32_t frame) const;
};

// A camera resolved for one image size: orthonormal basis (right-handed look-at,
// OpenGL style: the camera looks down -z of its own frame) and the focal length
// in pixels. If `up` is parallel to the view direction (looking straight up or
// down), +y, then +x, stands in for it (docs/pipeline.md).
struct CameraFrame {
    Vec3 eye{}, forward{}, right{}, upVector{};
    float focalPx = 1;  // H / (2 tan(fov/2))
    uint32_t width = 1, height = 1;
    float nearPlane = 1, farPlane = 1;

    // View-space depth along `forward` (> 0 in front of the eye).
    float Depth(const Vec3& p) const {
        return (p[0] - eye[0]) * forward[0] + (p[1] - eye[1]) * forward[1] + (p[2] - eye[2]) * forward[2];
    }
};

CameraFrame MakeCameraFrame(const CameraSettings& camera, uint32_t width, uint32_t height);

// The camera members every ray-casting GPU block has (GroundGpu, MarchGpu, LayersGpu): the eye (in the block's
// units), the focal length, the frame's axes with the near and far planes, h, and the image's size.
template <typename Block>
void SetCameraMembers(Block& g, const CameraFrame& c, const std::array<float, 3>& eye, float voxelSize) {
    g.eye = eye;
    g.focalPx = c.focalPx;
    g.forward = c.forward;
    g.nearPlane = c.nearPlane;
    g.right = c.right;
    g.farPlane = c.farPlane;
    g.up = c.upVector;
    g.voxelSize = voxelSize;
    g.width = c.width;
    g.height = c.height;
}

// Where a world point lands: pixel position (row 0 at the top) and depth.
// Follows SPEC 8: OpenGL-style perspective, px = (ndc_x + 1)/2 W,
// py = (1 - ndc_y)/2 H. Only meaningful for depth > 0.
struct Projected {
    float px, py, depth;
};
Projected Project(const CameraFrame& frame, const Vec3& p);

// The total back-to-front order of SPEC 8: axes by decreasing |view direction
// component| (ties: x before y before z), and along each axis the indices by
// decreasing |index + 0.5 - eye index|, ties by lower index.
struct SplatOrder {
    std::array<int, 3> axes{};                     // outermost first
    std::array<std::vector<uint32_t>, 3> indices;  // indices[axis]: that axis's order
};
SplatOrder MakeSplatOrder(const CameraFrame& frame, const Extent3& grid, const std::array<double, 3>& origin,
                          double voxelSize);

// The three axis orders of a SplatOrder in one array, outer axis first, as
// GPU shaders read them: base[level] is where level's order starts. Rank r
// is the voxel at outer order r / (nMid nIn), middle (r / nIn) % nMid, inner r % nIn.
struct FlatSplatOrder {
    std::vector<uint32_t> indices;
    std::array<uint32_t, 3> base{};
};
FlatSplatOrder FlattenSplatOrder(const SplatOrder& order);

// View-frustum culling of tile x height-band boxes (SPEC 8): 1 where a box of
// voxel centres may hold a splat that covers a pixel, 0 where it certainly
// does not (conservative; docs/pipeline.md derives the bound). Index
// tx + tilesX * (ty + tilesY * band), the layout of the density stage's bands.
std::vector<uint8_t> FrustumVisibleBoxes(const CameraFrame& camera, const Extent3& grid,
                                         const std::array<float, 3>& origin, float voxelSize, uint32_t tile,
                                         uint32_t band, float splatDiameter);

}  // namespace cb
