#include "core/math/Camera.h"

#include <algorithm>
#include <numbers>
#include <numeric>

namespace cb {
namespace {

std::array<double, 3> Sub(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
std::array<double, 3> Cross(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double Length(const std::array<double, 3>& a) { return std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }
std::array<double, 3> Normalize(const std::array<double, 3>& a) {
    const double l = Length(a);
    return {a[0] / l, a[1] / l, a[2] / l};
}
Vec3 ToFloat(const std::array<double, 3>& a) { return {float(a[0]), float(a[1]), float(a[2])}; }

}  // namespace

CameraSettings CameraSettings::At(uint32_t frame) const {
    CameraSettings pose = *this;
    pose.track.clear();
    if (track.empty()) return pose;
    auto set = [&pose](const CameraKeyframe& k) { pose.eye = k.eye, pose.target = k.target; };
    set(track.front());
    for (size_t i = 0; i + 1 < track.size(); ++i) {
        const CameraKeyframe &a = track[i], &b = track[i + 1];
        if (frame < a.frame) break;
        if (frame >= b.frame) {
            set(b);
            continue;
        }
        set(a);
        if (b.cut) break;
        const double w = double(frame - a.frame) / double(b.frame - a.frame);
        for (int c = 0; c < 3; ++c) {
            pose.eye[c] = a.eye[c] + (b.eye[c] - a.eye[c]) * w;
            pose.target[c] = a.target[c] + (b.target[c] - a.target[c]) * w;
        }
        break;
    }
    return pose;
}

bool CameraSettings::CutAt(uint32_t frame) const {
    return std::any_of(track.begin(), track.end(),
                       [frame](const CameraKeyframe& k) { return k.cut && k.frame == frame; });
}

CameraFrame MakeCameraFrame(const CameraSettings& camera, uint32_t width, uint32_t height) {
    CameraFrame frame;
    const std::array<double, 3> forward = Normalize(Sub(camera.target, camera.eye));
    std::array<double, 3> right = Cross(forward, camera.up);
    // Degenerate up (parallel to the view direction): +y, then +x, stands in.
    for (const std::array<double, 3>& fallback : {std::array<double, 3>{0, 1, 0}, std::array<double, 3>{1, 0, 0}}) {
        if (Length(right) > 1e-6 * Length(camera.up)) break;
        right = Cross(forward, fallback);
    }
    right = Normalize(right);
    const std::array<double, 3> up = Cross(right, forward);
    frame.eye = ToFloat(camera.eye);
    frame.forward = ToFloat(forward);
    frame.right = ToFloat(right);
    frame.upVector = ToFloat(up);
    frame.width = width;
    frame.height = height;
    frame.focalPx = float(double(height) / (2.0 * std::tan(camera.fovDeg * std::numbers::pi / 360.0)));
    frame.nearPlane = float(camera.nearPlane);
    frame.farPlane = float(camera.farPlane);
    return frame;
}

Projected Project(const CameraFrame& f, const Vec3& p) {
    const float dx = p[0] - f.eye[0], dy = p[1] - f.eye[1], dz = p[2] - f.eye[2];
    const float x = dx * f.right[0] + dy * f.right[1] + dz * f.right[2];
    const float y = dx * f.upVector[0] + dy * f.upVector[1] + dz * f.upVector[2];
    const float depth = dx * f.forward[0] + dy * f.forward[1] + dz * f.forward[2];
    // ndc_x = x f / (depth W/2), so px = W/2 + x f / depth; likewise py with y up.
    const float px = 0.5f * float(f.width) + x * f.focalPx / depth;
    const float py = 0.5f * float(f.height) - y * f.focalPx / depth;
    return {px, py, depth};
}

FlatSplatOrder FlattenSplatOrder(const SplatOrder& order) {
    FlatSplatOrder flat;
    for (int level = 0; level < 3; ++level) {
        flat.base[level] = uint32_t(flat.indices.size());
        const std::vector<uint32_t>& axis = order.indices[order.axes[level]];
        flat.indices.insert(flat.indices.end(), axis.begin(), axis.end());
    }
    return flat;
}

SplatOrder MakeSplatOrder(const CameraFrame& frame, const Extent3& grid, const std::array<double, 3>& origin,
                          double voxelSize) {
    SplatOrder order;
    std::array<int, 3> axes = {0, 1, 2};
    std::stable_sort(axes.begin(), axes.end(),
                     [&](int a, int b) { return std::fabs(frame.forward[a]) > std::fabs(frame.forward[b]); });
    order.axes = axes;
    const uint32_t sizes[3] = {grid.nx, grid.ny, grid.nz};
    for (int axis = 0; axis < 3; ++axis) {
        const double eyeIndex = (double(frame.eye[axis]) - origin[axis]) / voxelSize;
        std::vector<uint32_t>& idx = order.indices[axis];
        idx.resize(sizes[axis]);
        std::iota(idx.begin(), idx.end(), 0u);
        std::stable_sort(idx.begin(), idx.end(), [&](uint32_t a, uint32_t b) {
            const double da = std::fabs(a + 0.5 - eyeIndex), db = std::fabs(b + 0.5 - eyeIndex);
            return da > db;  // stable: ties keep the lower index first
        });
    }
    return order;
}

namespace {

// The four side planes of the frustum widened by one pixel; a voxel whose
// splat touches the image lies within splatDiameter/2 of their inside.
std::array<Vec3, 4> SidePlanes(const CameraFrame& c) {
    const float halfW = 0.5f * float(c.width) + 1.0f, halfH = 0.5f * float(c.height) + 1.0f;
    auto make = [&](const Vec3& axis, float sign, float half) {
        Vec3 n;
        for (int i = 0; i < 3; ++i) n[i] = sign * c.focalPx * axis[i] - half * c.forward[i];
        const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (float& x : n) x /= len;
        return n;
    };
    return {make(c.right, 1, halfW), make(c.right, -1, halfW), make(c.upVector, 1, halfH), make(c.upVector, -1, halfH)};
}

bool BoxCulled(const CameraFrame& c, const std::array<Vec3, 4>& planes, float radius, const Vec3& lo, const Vec3& hi) {
    float maxDepth = 0;  // the largest depth over the box
    for (int i = 0; i < 3; ++i)
        maxDepth += std::max((lo[i] - c.eye[i]) * c.forward[i], (hi[i] - c.eye[i]) * c.forward[i]);
    if (maxDepth <= c.nearPlane) return true;
    for (const Vec3& n : planes) {
        float minDistance = 0;  // the smallest n.(P - eye) over the box
        for (int i = 0; i < 3; ++i) minDistance += std::min((lo[i] - c.eye[i]) * n[i], (hi[i] - c.eye[i]) * n[i]);
        if (minDistance > radius) return true;
    }
    return false;
}

}  // namespace

std::vector<uint8_t> FrustumVisibleBoxes(const CameraFrame& camera, const Extent3& e,
                                         const std::array<float, 3>& origin, float h, uint32_t tile, uint32_t band,
                                         float splatDiameter) {
    const uint32_t tilesX = CeilDiv(e.nx, tile), tilesY = CeilDiv(e.ny, tile), bands = CeilDiv(e.nz, band);
    std::vector<uint8_t> visible(size_t(tilesX) * tilesY * bands, 1);
    const std::array<Vec3, 4> planes = SidePlanes(camera);
    for (uint32_t b = 0; b < bands; ++b)
        for (uint32_t ty = 0; ty < tilesY; ++ty)
            for (uint32_t tx = 0; tx < tilesX; ++tx) {
                // The box of the voxel centres in the tile-band.
                const Vec3 lo{origin[0] + (float(tx * tile) + 0.5f) * h, origin[1] + (float(ty * tile) + 0.5f) * h,
                              origin[2] + (float(b * band) + 0.5f) * h};
                const Vec3 hi{origin[0] + (float(std::min(e.nx, (tx + 1) * tile)) - 0.5f) * h,
                              origin[1] + (float(std::min(e.ny, (ty + 1) * tile)) - 0.5f) * h,
                              origin[2] + (float(std::min(e.nz, (b + 1) * band)) - 0.5f) * h};
                if (BoxCulled(camera, planes, 0.5f * splatDiameter, lo, hi))
                    visible[tx + size_t(tilesX) * (ty + size_t(tilesY) * b)] = 0;
            }
    return visible;
}

}  // namespace cb
