#include "core/Camera.h"

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

}  // namespace cb
