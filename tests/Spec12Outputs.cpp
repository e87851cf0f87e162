// SPEC 12's generic checks (tests/Spec12Outputs.h): every output array of a
// step, downloaded and checked against the range docs/contract.md documents for it.
#include "tests/Spec12Outputs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "core/math/Shading.h"
#include "registry/Registry.h"
#include "tests/TestUtil.h"

namespace cb::spec12_test {

Backend* BackendFor(const std::string& name, std::string& whyNot) {
    static std::map<std::string, std::unique_ptr<Backend>> made;
    static std::map<std::string, std::string> failed;
    if (auto it = made.find(name); it != made.end()) return it->second.get();
    if (auto it = failed.find(name); it != failed.end()) return whyNot = it->second, nullptr;
    auto backend = CreateBackend(name);
    if (!backend) return whyNot = failed[name] = backend.error().message, nullptr;
    return (made[name] = std::move(*backend)).get();
}

// Largest P^ = 4 pi p(theta) over theta (SPEC 9): at cos = sign(g), where both
// the numerator (1 + cos^2 for Cornette-Shanks) and 1/denominator peak.
double PhaseMax(const PhaseParams& phase) {
    const double g = std::fabs(double(phase.g));
    switch (phase.kind) {
        case PhaseKind::None: return 1;
        case PhaseKind::HenyeyGreenstein: return (1 + g) / ((1 - g) * (1 - g));
        case PhaseKind::CornetteShanks: return 3 * (1 - g * g) / ((2 + g * g) * std::pow(1 - g, 3));
        // Linear interpolation never exceeds the largest tabulated value.
        case PhaseKind::Mie:
            return *std::max_element(kMieCloudTable.values, kMieCloudTable.values + kMieCloudTable.count);
        // A blend of lobes convex in cos: its largest value is at cos = 1 or -1, where HG(g) is
        // (1 + g) / (1 - g)^2, respectively (1 - g) / (1 + g)^2.
        case PhaseKind::DualLobe: {
            const double f = phase.gForward, b = phase.gBackward, w = phase.blend;
            const double at1 = (1 - w) * (1 + f) / ((1 - f) * (1 - f)) + w * (1 + b) / ((1 - b) * (1 - b));
            const double atMinus1 = (1 - w) * (1 - f) / ((1 + f) * (1 + f)) + w * (1 - b) / ((1 + b) * (1 + b));
            return std::max(at1, atMinus1);
        }
    }
    return std::numeric_limits<double>::infinity();
}

// The documented range of element `index` of a resource. Images (SPEC 8, 10, 15):
// each pixel is a convex combination (compositing with alpha in [0, 1], or
// T_view weights summing to 1) of the background and of colours
// sun*T*P^ + ambient (+ sky*T_sky*P^ with the sky light) with T, T_sky in [0, 1], so each channel lies between
// min(background, ambient) and max(background, (sun + sky)*P^max + ambient).
struct Bounds {
    double lo, hi;
    bool zeroOrOne = false;
};
Bounds DocumentedBounds(Resource r, const Scene& s, size_t index) {
    switch (r) {
        case Resource::Region: return {0, 255};
        case Resource::Hum:
        case Resource::Act:
        case Resource::Cld:
        case Resource::Tiles:
        case Resource::Bands: return {0, 1, true};
        case Resource::Q: return {0, 1};                      // SPEC 4: a weighted mean of bits
        case Resource::ColumnSum: return {0, double(s.grid.size.nz)};  // SPEC 5: nz values of q
        case Resource::T:
        case Resource::TSky:
        case Resource::Shadow: return {0, 1};                 // SPEC 6, 7
        case Resource::SplatImage:
        case Resource::MarchImage:
        case Resource::LayersImage: {  // SPEC 15: the same blend, from the background
            const size_t c = index % 3;
            const double sky = s.lighting.sky.on ? double(s.lighting.sky.Radiance()[c]) : 0.0;
            const double sun = double(s.sun.Radiance()[c]) + sky, ambient = s.lighting.ambient[c],
                         bg = s.lighting.background[c];
            const double lo = std::min(bg, ambient), hi = std::max(bg, sun * PhaseMax(s.phase) + ambient);
            return {lo * (1 - 1e-5), hi * (1 + 1e-5)};  // float rounding of the blends
        }
    }
    return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
}

std::vector<float> DownloadAsFloat(Backend& backend, const Buffer& buffer) {
    if (buffer.Format() == BufferFormat::F32) return test::Read<float>(backend, buffer);
    const std::vector<uint8_t> bytes = test::Read<uint8_t>(backend, buffer);
    return std::vector<float>(bytes.begin(), bytes.end());
}

void CheckArray(Resource r, const Scene& s, const std::vector<float>& values, const std::string& what) {
    size_t bad = 0, first = values.size();
    for (size_t n = 0; n < values.size(); ++n) {
        const float v = values[n];
        const Bounds b = DocumentedBounds(r, s, n);
        bool ok = std::isfinite(v) && v >= b.lo && v <= b.hi;
        if (b.zeroOrOne) ok = ok && (v == 0 || v == 1);
        if (r == Resource::T) ok = ok && (v == 0 || v >= kTransmittanceFloor);
        if (!ok) {
            if (first == values.size()) first = n;
            ++bad;
        }
    }
    if (bad > 0) {
        const Bounds b = DocumentedBounds(r, s, first);
        ADD_FAILURE() << what << ": " << bad << " of " << values.size() << " values outside the documented range; first ["
                      << first << "] = " << values[first] << ", allowed [" << b.lo << ", " << b.hi << "]"
                      << (b.zeroOrOne ? " as 0 or 1" : "") << (r == Resource::T ? ", 0 or >= 1e-30" : "");
    }
}

Snapshot CheckEveryOutput(const Simulation& sim, uint32_t step, std::optional<uint32_t> cover, size_t& arraysChecked) {
    const Scene& scene = sim.GetScene();
    Backend& backend = sim.GetBackend();
    Snapshot snap;
    snap.step = step;
    snap.coveredColumns = cover;
    for (Stage stage : sim.Schedule()) {
        for (Resource r : Describe(stage).writes) {
            if (snap.Has(r)) continue;
            const size_t buffers = IsPerCamera(r) ? scene.render.cameras.size() : 1;
            for (size_t n = 0; n < buffers; ++n) {
                const Buffer* buffer = sim.Get(r, n);
                if (!buffer) {
                    ADD_FAILURE() << StageName(stage) << " writes " << ResourceName(r) << " but it has no buffer " << n;
                    continue;
                }
                EXPECT_EQ(buffer->Extent(), ResourceExtent(r, scene)) << ResourceName(r);
                snap.current[size_t(r)].push_back(DownloadAsFloat(backend, *buffer));
                CheckArray(r, scene, snap.current[size_t(r)].back(),
                           std::string(ResourceName(r)) + "[" + std::to_string(n) + "] at step " + std::to_string(step));
                ++arraysChecked;
            }
            if (const Buffer* previous = sim.Previous(r)) {
                CheckArray(r, scene, DownloadAsFloat(backend, *previous),
                           "previous " + std::string(ResourceName(r)) + " at step " + std::to_string(step));
                ++arraysChecked;
            }
        }
    }
    return snap;
}

}  // namespace cb::spec12_test
