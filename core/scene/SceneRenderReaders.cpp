// Readers of the lighting and rendering sections every stage shares (sun,
// lighting, phase, render with its cameras).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>
#include <utility>

#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kSunKeys[] = {"elevation_deg", "azimuth_deg", "color", "intensity", "path", "speed"};
constexpr std::string_view kSunKeyframeKeys[] = {"step", "elevation_deg", "azimuth_deg"};
constexpr std::string_view kSunSpeedKeys[] = {"elevation_deg", "azimuth_deg"};
constexpr std::string_view kPhaseKeys[] = {"function", "g", "g_forward", "g_backward", "blend"};
constexpr std::string_view kRenderKeys[] = {
    "width",    "height",      "q_min",           "splat_scale",      "opacity", "alpha", "culling",
    "skipping", "every_steps", "frames_per_step", "slices_per_frame", "cameras", "ground"};
constexpr std::string_view kGroundKeys[] = {"albedo"};
constexpr std::string_view kCameraKeys[] = {"name", "eye", "target", "up", "fov_deg", "near", "far", "track"};
constexpr std::string_view kCameraKeyframeKeys[] = {"frame", "eye", "target", "cut"};

// An eye and a target that differ; false (and a message at `field`) where they are equal.
bool CheckEyeAndTarget(const std::array<double, 3>& eye, const std::array<double, 3>& target, const std::string& field,
                       Validator& check) {
    if (eye != target) return true;
    check.Fail(field, "must differ from eye");
    return false;
}

// A camera's track (CameraSettings::track): keyframes by strictly increasing frame, each with its eye and target.
// Between two keyframes that are not a cut the eye and the target move linearly; a segment along which the view
// direction turns through 180 degrees would pass through eye = target on the way and is refused.
std::vector<CameraKeyframe> ReadCameraTrack(const Json& value, const std::string& field, Validator& check) {
    std::vector<CameraKeyframe> track;
    if (!value.is_array() || value.empty()) {
        check.Fail(field, "expected a non-empty array of keyframes {frame, eye, target, cut}, got " + Describe(value));
        return track;
    }
    for (size_t i = 0; i < value.size(); ++i) {
        const std::string at = IndexField(field, i);
        const Json& entry = value[i];
        if (!entry.is_object()) {
            check.Fail(at, "expected a keyframe object {frame, eye, target, cut}, got " + Describe(entry));
            continue;
        }
        check.CheckKeys(entry, at, kCameraKeyframeKeys);
        CameraKeyframe k;
        bool ok = true;
        for (std::string_view key : {std::string_view("frame"), std::string_view("eye"), std::string_view("target")})
            if (!Validator::Find(entry, key)) {
                check.Fail(JoinField(at, key), "required field is missing");
                ok = false;
            }
        if (const Json* v = Validator::Find(entry, "frame")) {
            if (auto n = check.Integer(*v, JoinField(at, "frame"), 0, kU32Max))
                k.frame = uint32_t(*n);
            else
                ok = false;
        }
        if (const Json* v = Validator::Find(entry, "eye")) {
            if (auto a = check.Numbers<3>(*v, JoinField(at, "eye"), kFinite))
                k.eye = *a;
            else
                ok = false;
        }
        if (const Json* v = Validator::Find(entry, "target")) {
            if (auto a = check.Numbers<3>(*v, JoinField(at, "target"), kFinite))
                k.target = *a;
            else
                ok = false;
        }
        if (const Json* v = Validator::Find(entry, "cut")) {
            if (auto b = check.Boolean(*v, JoinField(at, "cut")))
                k.cut = *b;
            else
                ok = false;
        }
        if (!ok || !CheckEyeAndTarget(k.eye, k.target, JoinField(at, "target"), check)) continue;
        if (!track.empty() && k.frame <= track.back().frame) {
            check.Fail(JoinField(at, "frame"), "keyframes must come by increasing frame, got " +
                                                   std::to_string(k.frame) + " after " +
                                                   std::to_string(track.back().frame));
            continue;
        }
        if (!track.empty() && !k.cut) {
            const CameraKeyframe& p = track.back();
            double a[3], b[3];
            for (int c = 0; c < 3; ++c) a[c] = p.target[c] - p.eye[c], b[c] = k.target[c] - k.eye[c];
            const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
            const double cross[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
            const double crossLength = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
            if (dot < 0 && crossLength <= 1e-9 * std::sqrt(dot * dot)) {
                check.Fail(JoinField(at, "target"),
                           "the view direction turns through 180 degrees from the previous keyframe, so the "
                           "camera would pass through eye = target on the way; add a keyframe between them or "
                           "mark this one as a cut");
                continue;
            }
        }
        track.push_back(k);
    }
    return track;
}

constexpr int64_t kMaxImageEdge = 16384;
constexpr int64_t kMaxFramesPerStep = 1024;

// One entry of render.cameras; nullopt when anything in it is wrong (all of it reported).
std::optional<CameraSettings> ReadCamera(const Json& value, const std::string& field, size_t index, Validator& check) {
    if (!value.is_object()) {
        check.Fail(field, "expected a camera object, got " + Describe(value));
        return std::nullopt;
    }
    const size_t errorsBefore = check.ErrorCount();
    check.CheckKeys(value, field, kCameraKeys);
    auto find = [&](std::string_view key) { return Validator::Find(value, key); };
    auto sub = [&](std::string_view key) { return JoinField(field, key); };

    CameraSettings camera;
    // The name becomes part of frame file names (frame-<renderer>-<camera>-<backend>.png): kPathNameRule.
    camera.name = "view" + std::to_string(index);
    if (const Json* v = find("name")) {
        if (auto s = check.PathName(*v, sub("name"))) camera.name = *s;
    }
    if (const Json* track = find("track")) {
        // The track gives every pose; a fixed eye or target beside it would be ignored, so it is refused.
        for (std::string_view key : {std::string_view("eye"), std::string_view("target")})
            if (find(key))
                check.Fail(sub(key),
                           "cannot be combined with track (the track's keyframes give the pose); remove "
                           "one");
        camera.track = ReadCameraTrack(*track, sub("track"), check);
        if (!camera.track.empty()) camera.eye = camera.track.front().eye, camera.target = camera.track.front().target;
    } else {
        std::optional<std::array<double, 3>> eye, target;
        if (const Json* v = find("eye")) {
            eye = check.Numbers<3>(*v, sub("eye"), kFinite);
        } else {
            check.Fail(sub("eye"), "required field is missing");
        }
        if (const Json* v = find("target")) {
            target = check.Numbers<3>(*v, sub("target"), kFinite);
        } else {
            check.Fail(sub("target"), "required field is missing");
        }
        if (eye && target) CheckEyeAndTarget(*eye, *target, sub("target"), check);
        if (eye) camera.eye = *eye;
        if (target) camera.target = *target;
    }
    if (const Json* v = find("up")) {
        if (auto a = check.Numbers<3>(*v, sub("up"), kFinite)) {
            if ((*a)[0] == 0 && (*a)[1] == 0 && (*a)[2] == 0)
                check.Fail(sub("up"), "must not be all zero, got " + Describe(*v));
            else
                camera.up = *a;
        }
    }
    if (const Json* v = find("fov_deg")) {
        const Range fov{.lo = 0, .loOpen = true, .hi = 180, .hiOpen = true};
        if (auto d = check.Number(*v, sub("fov_deg"), fov)) camera.fovDeg = *d;
    }
    // far must exceed near; the message names whichever of the two the file gave (far when both).
    bool nearOk = true, farOk = true;
    if (const Json* v = find("near")) {
        auto d = check.Number(*v, sub("near"), kPositive);
        if (d) camera.nearPlane = *d;
        nearOk = d.has_value();
    }
    const Json* far = find("far");
    if (far) {
        auto d = check.Number(*far, sub("far"), kFinite);
        if (d) camera.farPlane = *d;
        farOk = d.has_value();
    }
    if (nearOk && farOk && camera.farPlane <= camera.nearPlane) {
        if (far)
            check.Fail(sub("far"),
                       "must be > near (" + FormatNumber(camera.nearPlane) + "), got " + FormatNumber(camera.farPlane));
        else
            check.Fail(sub("near"),
                       "must be < far (" + FormatNumber(camera.farPlane) + "), got " + FormatNumber(camera.nearPlane));
    }
    if (check.ErrorCount() != errorsBefore) return std::nullopt;
    return camera;
}

// An azimuth in degrees: finite, and within kMaxAzimuthDeg (CheckAzimuth).
std::optional<double> ReadAzimuth(const Json& value, const std::string& field, Validator& check) {
    std::optional<double> d = check.Number(value, field, kFinite);
    if (d && !CheckAzimuth(*d, field, "", check)) return std::nullopt;
    return d;
}

}  // namespace

// The largest |azimuth| the sun may reach, in degrees. The code evaluates the
// angle in double (a path's interpolation lo + (hi - lo) w, or the speed's
// az + speed t; then times pi/180, core/scene/Scene.h DirectionAt) and rounds cos and
// sin to float. Those roundings cost at most 3 ulps of the angle in radians,
// 3 * 2^-52 * 1e9 * pi/180 = 1.2e-8 rad here, below half an ulp of float at 1,
// 2^-25 = 3.0e-8: the float direction is the angle's. Past about 2.6e9 degrees
// it is not, and at 1e308 a path's hi - lo overflows to inf and the direction
// becomes NaN.
constexpr double kMaxAzimuthDeg = 1e9;

bool CheckAzimuth(double degrees, const std::string& field, std::string_view where, Validator& check) {
    if (std::fabs(degrees) <= kMaxAzimuthDeg) return true;
    check.Fail(field, "the azimuth must be in [-" + FormatNumber(kMaxAzimuthDeg) + ", " + FormatNumber(kMaxAzimuthDeg) +
                          "] degrees (beyond, double precision no longer fixes the sun's direction to float's "
                          "precision), got " +
                          FormatNumber(degrees) + std::string(where));
    return false;
}

void ReadSun(const Json& root, Validator& check, SunSettings& sun) {
    const Json* section = check.Section(root, "", "sun", kSunKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "elevation_deg")) {
        if (auto d = check.Number(*v, "sun.elevation_deg", Range{.lo = -90, .hi = 90})) sun.elevationDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "azimuth_deg")) {
        if (auto d = ReadAzimuth(*v, "sun.azimuth_deg", check)) sun.azimuthDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "color")) {
        if (auto a = check.Numbers<3>(*v, "sun.color", kSingleNonNegative)) sun.color = *a;
    }
    if (const Json* v = Validator::Find(*section, "intensity")) {
        if (auto d = check.Number(*v, "sun.intensity", kSingleNonNegative)) sun.intensity = *d;
    }
    // A path: keyframes {step, elevation_deg, azimuth_deg} in increasing step order; it replaces the fixed angles.
    const Json* path = Validator::Find(*section, "path");
    const Json* speed = Validator::Find(*section, "speed");
    if (path) {
        for (std::string_view key : {"elevation_deg", "azimuth_deg", "speed"})
            if (Validator::Find(*section, key))
                check.Fail(JoinField("sun", key),
                           "cannot be combined with sun.path (the keyframes give the sun's angles)");
        if (!path->is_array() || path->empty()) {
            check.Fail("sun.path",
                       "expected a non-empty array of keyframes {\"step\", \"elevation_deg\", "
                       "\"azimuth_deg\"}, got " +
                           Describe(*path));
        } else {
            std::vector<SunKeyframe> keyframes;
            bool pathOk = true;
            for (size_t i = 0; i < path->size(); ++i) {
                const Json& k = (*path)[i];
                const std::string field = IndexField("sun.path", i);
                if (!k.is_object()) {
                    check.Fail(field,
                               "expected a keyframe object {\"step\", \"elevation_deg\", \"azimuth_deg\"}, got " +
                                   Describe(k));
                    pathOk = false;
                    continue;
                }
                check.CheckKeys(k, field, kSunKeyframeKeys);
                SunKeyframe frame;
                std::optional<int64_t> step;
                std::optional<double> el, az;
                if (const Json* v = Validator::Find(k, "step"))
                    step = check.Integer(*v, JoinField(field, "step"), 0, kU32Max);
                else
                    check.Fail(JoinField(field, "step"), "required field is missing");
                if (const Json* v = Validator::Find(k, "elevation_deg"))
                    el = check.Number(*v, JoinField(field, "elevation_deg"), Range{.lo = -90, .hi = 90});
                else
                    check.Fail(JoinField(field, "elevation_deg"), "required field is missing");
                if (const Json* v = Validator::Find(k, "azimuth_deg"))
                    az = ReadAzimuth(*v, JoinField(field, "azimuth_deg"), check);
                else
                    check.Fail(JoinField(field, "azimuth_deg"), "required field is missing");
                if (!step || !el || !az) {
                    pathOk = false;
                    continue;
                }
                frame = {uint32_t(*step), *el, *az};
                const std::optional<uint32_t> previous =
                    keyframes.empty() ? std::nullopt : std::optional(keyframes.back().step);
                if (!check.StepAfterPrevious(JoinField(field, "step"), previous, frame.step)) {
                    pathOk = false;
                    continue;
                }
                keyframes.push_back(frame);
            }
            if (pathOk) {
                sun.path = std::move(keyframes);
                sun.elevationDeg = sun.ElevationAt(0);
                sun.azimuthDeg = sun.AzimuthAt(0);
            }
        }
    } else if (speed) {
        // Degrees per step; the elevation's range over the run is checked with the step count (CheckSunPath).
        if (const Json* s = check.Section(*section, "sun", "speed", kSunSpeedKeys)) {
            if (const Json* v = Validator::Find(*s, "elevation_deg")) {
                if (auto d = check.Number(*v, "sun.speed.elevation_deg", Range{.lo = -180, .hi = 180}))
                    sun.elevationSpeedDeg = *d;
            }
            if (const Json* v = Validator::Find(*s, "azimuth_deg")) {
                if (auto d = check.Number(*v, "sun.speed.azimuth_deg", Range{.lo = -360, .hi = 360}))
                    sun.azimuthSpeedDeg = *d;
            }
        }
    }
    // The radiance color * intensity is what the renderers use, in single precision. With it, the lightning's
    // (ReadLightning, core/pipeline/LightTerms.cpp), ambient and background each at most 1e30 and every P^ at most
    // 2^19.5 (ReadPhase), every output stays finite (float's largest is 3.4e38):
    //   a sample's light  sun T P^ powder + ambient + lightning T P^ / max(D^2, r0^2)
    //                     <= 1e30 * 2^19.5 + 1e30 + 1e30 * 2^19.5 < 1.5e36 (T, powder <= 1);
    //   a march pixel     L + T_view background, L = sum of T_n (1 - tau_n) * light_n: the float weights sum to at
    //                     most 2 (each step's weight is at most twice the drop of the float T_view, which starts at
    //                     1), and each float add of a positive x to a sum rounds it up by at most 2x, so
    //                     L <= 6 * 1.5e36 and the pixel <= 9e36 + 1e30;
    //   a splat pixel     a blend C (1 - a) + c a of the background (or the ground) and colours <= 7.5e35 + 1e30;
    //   the ground        albedo (sun max(s_z, 0) G + ambient) <= 2e30.
    const double brightest = std::max({sun.color[0], sun.color[1], sun.color[2]}) * sun.intensity;
    if (brightest > kMaxSingle)
        check.Fail("sun.intensity",
                   "color * intensity (the sun's radiance) must be at most 1e+30 in each channel, got " +
                       FormatNumber(brightest));
}

void ReadPhase(const Json& root, Validator& check, PhaseParams& phase) {
    const Json* section = check.Section(root, "", "phase", kPhaseKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "function")) {
        if (auto kind = check.Choice(*v, "phase.function", kPhaseKindNames)) phase.kind = *kind;
    }
    const Json* gValue = Validator::Find(*section, "g");
    if (const Json* v = gValue) {
        if (auto d = check.Number(*v, "phase.g", Range{.lo = -1, .loOpen = true, .hi = 1, .hiOpen = true})) {
            // g is kept as a float: a value within 2^-25 of +-1 would become +-1 there.
            if (std::fabs(float(*d)) >= 1.0f)
                check.Fail("phase.g", "must be in (-1, 1) in single precision, got " + Describe(*v));
            else
                phase.g = float(*d);
        }
    }
    // The dual lobe's fields, read whatever the function (as g is): only dual-lobe uses them. A g stays a float
    // inside its half-open range there too.
    struct LobeField {
        const char* key;
        float& value;
        Range range;
        const char* rangeText;
    };
    const LobeField lobes[] = {
        {"g_forward", phase.gForward, Range{.lo = 0, .hi = 1, .hiOpen = true}, "[0, 1)"},
        {"g_backward", phase.gBackward, Range{.lo = -1, .loOpen = true, .hi = 0}, "(-1, 0]"},
        {"blend", phase.blend, Range{.lo = 0, .hi = 1}, "[0, 1]"},
    };
    for (const LobeField& lobe : lobes) {
        const Json* v = Validator::Find(*section, lobe.key);
        if (!v) continue;
        const std::string field = std::string("phase.") + lobe.key;
        if (auto d = check.Number(*v, field, lobe.range)) {
            if (std::string_view(lobe.key) != "blend" && std::fabs(float(*d)) >= 1.0f)
                check.Fail(field,
                           "must be in " + std::string(lobe.rangeText) + " in single precision, got " + Describe(*v));
            else
                lobe.value = float(*d);
        }
    }
    if (phase.kind == PhaseKind::DualLobe) {
        // Each lobe within the peak bound, whatever its weight (a weight of 0 times an infinite lobe is NaN); the
        // blend of two such lobes may round a few ulps above the larger, so it is bounded too.
        struct LobeEnd {
            const char* field;
            const char* cosTheta;
            float peak;
        };
        const LobeEnd ends[] = {{"phase.g_forward", "1", HenyeyGreenstein(phase.gForward, 1.0f)},
                                {"phase.g_backward", "-1", HenyeyGreenstein(phase.gBackward, -1.0f)}};
        bool lobesBounded = true;
        for (const LobeEnd& end : ends)
            if (!(end.peak <= kMaxPhasePeak)) {
                lobesBounded = false;
                check.Fail(end.field, std::string("the lobe's peak (Henyey-Greenstein at cos theta = ") + end.cosTheta +
                                          ", in single precision as the stages evaluate it) must be at most " +
                                          FormatNumber(kMaxPhasePeak) + " (2^18), got " + FormatNumber(end.peak));
            }
        const float peak = PhasePeak(phase);
        if (lobesBounded && !(peak <= kMaxPhasePeak))
            check.Fail("phase.blend", "the blended peak P^max must be at most " + FormatNumber(kMaxPhasePeak) +
                                          " (2^18), got " + FormatNumber(peak));
        return;
    }
    // The peak bounds every P^ the stages form (core/math/Shading.h kMaxPhasePeak); only g moves it (Mie's is ~7400).
    const float peak = PhasePeak(phase);
    if (!(peak <= kMaxPhasePeak))
        check.Fail("phase.g",
                   "the phase function's peak P^max (P^ at cos theta = " + std::string(phase.g < 0 ? "-1" : "1") +
                       ", in single precision as the stages evaluate it) must be at most " +
                       FormatNumber(kMaxPhasePeak) + " (2^18), got " + FormatNumber(peak) + " (" +
                       std::string(PhaseKindName(phase.kind)) +
                       ", g = " + (gValue ? Describe(*gValue) : FormatNumber(phase.g)) + ")");
}

bool ReadRender(const Json& root, Validator& check, RenderSettings& render) {
    const Json* section = check.Section(root, "", "render", kRenderKeys);
    if (!section) return true;
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    auto field = [](std::string_view key) { return JoinField("render", key); };

    if (const Json* v = find("width")) {
        if (auto n = check.Integer(*v, field("width"), 1, kMaxImageEdge)) render.width = uint32_t(*n);
    }
    if (const Json* v = find("height")) {
        if (auto n = check.Integer(*v, field("height"), 1, kMaxImageEdge)) render.height = uint32_t(*n);
    }
    if (const Json* v = find("alpha")) {
        if (auto d = check.Number(*v, field("alpha"), kProbability)) render.alpha = *d;
    }
    if (const Json* v = find("every_steps")) {
        if (auto n = check.Integer(*v, field("every_steps"), 0, kU32Max)) render.everySteps = uint32_t(*n);
    }
    if (const Json* v = find("frames_per_step")) {
        if (auto n = check.Integer(*v, field("frames_per_step"), 1, kMaxFramesPerStep)) {
            render.framesPerStep = uint32_t(*n);
            // F > 1 frames run alpha from 1/F to 1 themselves: a fixed alpha beside them would be ignored.
            if (render.framesPerStep > 1 && find("alpha"))
                check.Fail(field("alpha"),
                           "cannot be combined with render.frames_per_step > 1 (the frames run alpha "
                           "from 1/F to 1); remove one");
        }
    }

    if (const Json* v = find("slices_per_frame")) {
        if (auto n = check.Integer(*v, field("slices_per_frame"), 0, kU32Max)) {
            render.slicesPerFrame = uint32_t(*n);
            // Time-sliced frames run alpha over the step's frames, however many the shares take.
            if (render.slicesPerFrame > 0 && find("alpha"))
                check.Fail(field("alpha"),
                           "cannot be combined with render.slices_per_frame > 0 (the frames of a "
                           "time-sliced step run alpha from 1/F to 1); remove one");
        }
    }

    if (const Json* ground = check.Section(*section, "render", "ground", kGroundKeys)) {
        render.ground.on = true;
        if (const Json* v = Validator::Find(*ground, "albedo")) {
            if (auto a = check.Numbers<3>(*v, "render.ground.albedo", kProbability)) render.ground.albedo = *a;
        }
    }

    const Json* cameras = find("cameras");
    if (!cameras) return true;
    if (!cameras->is_array()) {
        check.Fail(field("cameras"), "expected an array of camera objects, got " + Describe(*cameras));
        return false;
    }
    bool allOk = true;
    render.cameras.clear();
    for (size_t i = 0; i < cameras->size(); ++i) {
        const std::string cameraField = IndexField(field("cameras"), i);
        std::optional<CameraSettings> camera = ReadCamera((*cameras)[i], cameraField, i, check);
        if (!camera) {
            allOk = false;
            continue;
        }
        const bool duplicate = std::any_of(render.cameras.begin(), render.cameras.end(),
                                           [&](const CameraSettings& c) { return c.name == camera->name; });
        if (duplicate) {
            // A defaulted name ("view1") can clash with a name given earlier; say so, since the file has no name here.
            const bool given = Validator::Find((*cameras)[i], "name") != nullptr;
            check.Fail(JoinField(cameraField, "name"),
                       "duplicate camera name " + Quote(camera->name) + (given ? "" : " (its default name)"));
            allOk = false;
            continue;
        }
        render.cameras.push_back(std::move(*camera));
    }
    return allOk;
}

}  // namespace cb::scene_io
