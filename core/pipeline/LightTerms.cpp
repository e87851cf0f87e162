#include "core/pipeline/LightTerms.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include "core/scene/SceneNames.h"
#include "core/scene/SceneReaders.h"

namespace cb {

LightTerms MakeLightTerms(const Scene& sc, uint32_t step) {
    LightTerms L;
    L.sunRadiance = sc.sun.Radiance();
    L.ambient = sc.lighting.Ambient();
    L.phase = sc.phase;
    L.voxelSize = float(sc.grid.voxelSize);
    const LightningSettings& l = sc.lightning;
    L.pointOn = l.OnAt(step);
    for (int c = 0; c < 3; ++c) {
        L.pointPosition[c] = float((l.position[c] - sc.grid.origin[c]) / sc.grid.voxelSize);
        L.pointRadiance[c] = float(l.color[c] * l.intensity);
    }
    L.pointMinDistance2 = float(l.radius * l.radius);
    L.invThickness = 1.0f / float(std::max(sc.grid.size.nz, 1u));
    // City glow in voxel units. The clamps keep every product of GlowMap finite or +inf, never NaN, whatever the
    // voxel size: a centre at most 1e18 voxel edges out, k = h^2 / (2 sigma^2) at most 1e30 (0 * k is 0).
    const CityGlowSettings& glow = sc.lighting.cityGlow;
    L.glowOn = glow.on;
    if (glow.on) {
        const double h = sc.grid.voxelSize;
        for (int c = 0; c < 3; ++c) L.glowColor[c] = float(glow.color[c]);
        L.glowFade = float(glow.fade);
        L.glowBlobCount = uint32_t(std::min<size_t>(glow.blobs.size(), kMaxGlowBlobs));
        for (uint32_t i = 0; i < L.glowBlobCount; ++i) {
            const CityGlowSettings::Blob& b = glow.blobs[i];
            for (int c = 0; c < 2; ++c)
                L.glowBlobs[i][c] = float(std::clamp((b.center[c] - sc.grid.origin[c]) / h, -1e18, 1e18));
            L.glowBlobs[i][2] = float(std::min(h * h / (2 * b.radius * b.radius), 1e30));
            L.glowBlobs[i][3] = float(b.strength);
        }
    }
    const SkyLightSettings& sky = sc.lighting.sky;
    L.skyOn = sky.on;
    if (sky.on) {
        L.skyRadiance = sky.Radiance();
        L.skyDirection = sky.Direction();
    }
    const OctaveSettings& octaves = sc.lighting.octaves;
    L.octaves = octaves.count;
    if (octaves.count > 1) {
        L.octaveAttenuation = float(octaves.attenuation);
        L.octaveContribution = float(octaves.contribution);
        L.octaveEccentricity = float(octaves.eccentricity);
    }
    const EyeScatteringSettings& eye = sc.lighting.eyeScattering;
    L.eyeOn = eye.on;
    L.sunDirection = sc.sun.DirectionAt(step);
    if (eye.on) {
        const double cosCone = std::cos(eye.coneDeg * std::numbers::pi / 180);
        L.eyeIntensity = float(eye.intensity);
        L.eyeCosCone = float(cosCone);
        L.eyeInvOneMinusCos = float(1 / (1 - cosCone));
        L.eyeHeightGain = float(eye.heightGain);
        if (eye.replacesPhase) L.phase = PhaseParams{PhaseKind::None, 0.0f};
    }
    return L;
}

}  // namespace cb

namespace cb::scene_io {
namespace {

constexpr std::string_view kLightingKeys[] = {"ambient", "background", "city_glow", "eye_scattering",
                                              "sky",     "octaves",    "shafts"};
constexpr std::string_view kShaftsKeys[] = {"shells", "extinction", "g", "falloff_deg"};
constexpr std::string_view kOctaveKeys[] = {"count", "attenuation", "contribution", "eccentricity"};
constexpr std::string_view kSkyKeys[] = {"elevation_deg", "azimuth_deg", "color", "intensity"};
constexpr std::string_view kEyeScatteringKeys[] = {"intensity", "cone_deg", "height_gain", "replaces_phase"};
constexpr std::string_view kCityGlowKeys[] = {"color", "fade", "blobs"};
constexpr std::string_view kGlowBlobKeys[] = {"center", "radius", "strength"};
// City glow's colour, strength and fade: bounded so that a sample's glow (at most kMaxGlowBlobs * 1e6 * 1e6)
// stays far below the sun's bound (ReadSun); centres within float's reach; radii that a voxel size can resolve.
constexpr Range kGlowValue{.lo = 0, .hi = 1e6};
constexpr Range kGlowCenter{.lo = -1e15, .hi = 1e15};
constexpr Range kGlowRadius{.lo = 1e-6, .hi = 1e15};

// I_e is at most intensity (height_gain + 1) <= 1e3 * 101, below every P^'s bound 2^19.5 (core/math/Shading.h
// kMaxPhasePeak): the term adds no more than the sun's own, and ReadSun's bound on a sample's light holds.
void ReadEyeScattering(const Json& lighting, Validator& check, EyeScatteringSettings& eye) {
    const Json* section = check.Section(lighting, "lighting", "eye_scattering", kEyeScatteringKeys);
    if (!section) return;
    eye.on = true;
    if (const Json* v = Validator::Find(*section, "intensity")) {
        if (auto d = check.Number(*v, "lighting.eye_scattering.intensity", Range{.lo = 0, .hi = 1e3}))
            eye.intensity = *d;
    }
    // At most 1e-3 degrees narrow, so that 1 - cos(cone) (about 1.5e-10) stays a normal number in double and float.
    if (const Json* v = Validator::Find(*section, "cone_deg")) {
        if (auto d = check.Number(*v, "lighting.eye_scattering.cone_deg", Range{.lo = 1e-3, .hi = 180}))
            eye.coneDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "height_gain")) {
        if (auto d = check.Number(*v, "lighting.eye_scattering.height_gain", Range{.lo = 0, .hi = 100}))
            eye.heightGain = *d;
    }
    if (const Json* v = Validator::Find(*section, "replaces_phase")) {
        if (auto b = check.Boolean(*v, "lighting.eye_scattering.replaces_phase")) eye.replacesPhase = *b;
    }
}

// Octaves: count in [1, kMaxOctaves]; a in (0, 1] (T^0 would light a sample however deep in cloud; GLSL's pow(0, 0)
// is undefined), b and c in [0, 1], and a <= b (Wrenninge, Kulla and Lundqvist's condition for energy
// conservation). The sum is at most count times the sun's single-scattering gain: ReadSun's bound holds with 8x.
void ReadOctaves(const Json& lighting, Validator& check, OctaveSettings& octaves) {
    const Json* section = check.Section(lighting, "lighting", "octaves", kOctaveKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "count")) {
        if (auto n = check.Integer(*v, "lighting.octaves.count", 1, kMaxOctaves)) octaves.count = uint32_t(*n);
    }
    if (const Json* v = Validator::Find(*section, "attenuation")) {
        if (auto d = check.Number(*v, "lighting.octaves.attenuation", Range{.lo = 0, .loOpen = true, .hi = 1}))
            octaves.attenuation = *d;
    }
    if (const Json* v = Validator::Find(*section, "contribution")) {
        if (auto d = check.Number(*v, "lighting.octaves.contribution", Range{.lo = 0, .hi = 1}))
            octaves.contribution = *d;
    }
    if (const Json* v = Validator::Find(*section, "eccentricity")) {
        if (auto d = check.Number(*v, "lighting.octaves.eccentricity", Range{.lo = 0, .hi = 1}))
            octaves.eccentricity = *d;
    }
    if (octaves.attenuation > octaves.contribution)
        check.Fail("lighting.octaves.attenuation",
                   "must be at most contribution (" + FormatNumber(octaves.contribution) +
                       ": an octave's light may not fall slower than its extinction, or the octaves add energy), got " +
                       FormatNumber(octaves.attenuation));
}

// The sky light is scattered sunlight from the sky above the horizon: its elevation is in (0, 90] (below the
// horizon is the ground's side; a light there would light the clouds through the ground). colour * intensity is
// bounded like the sun's (ReadSun), so the term adds at most what the sun does to a sample's light.
void ReadSky(const Json& lighting, Validator& check, SkyLightSettings& sky) {
    const Json* section = check.Section(lighting, "lighting", "sky", kSkyKeys);
    if (!section) return;
    sky.on = true;
    if (const Json* v = Validator::Find(*section, "elevation_deg")) {
        if (v->is_number() && v->get<double>() <= 0)
            check.Fail("lighting.sky.elevation_deg",
                       "the sky light shines from above the horizon (elevation in (0, 90] degrees; below is the "
                       "ground), got " +
                           FormatNumber(v->get<double>()));
        else if (auto d = check.Number(*v, "lighting.sky.elevation_deg", Range{.lo = 0, .loOpen = true, .hi = 90}))
            sky.elevationDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "azimuth_deg")) {
        if (auto d = check.Number(*v, "lighting.sky.azimuth_deg", Range{.lo = -360, .hi = 360})) sky.azimuthDeg = *d;
    }
    if (const Json* v = Validator::Find(*section, "color")) {
        if (auto a = check.Numbers<3>(*v, "lighting.sky.color", kSingleNonNegative)) sky.color = *a;
    }
    if (const Json* v = Validator::Find(*section, "intensity")) {
        if (auto d = check.Number(*v, "lighting.sky.intensity", kSingleNonNegative)) sky.intensity = *d;
    }
    const double brightest = std::max({sky.color[0], sky.color[1], sky.color[2]}) * sky.intensity;
    if (brightest > kMaxSingle)
        check.Fail("lighting.sky.intensity",
                   "color * intensity (the sky light's radiance) must be at most 1e+30 in each channel, got " +
                       FormatNumber(brightest));
}

// Shafts of light: S in [1, kMaxShafts] shells; a haze of extinction in (0, 1] per metre (at 1 per metre the haze
// hides everything past a few metres); an HG eccentricity within (-1, 1) whose P^ stays below kMaxPhasePeak
// (|g| <= 0.99: P^ <= 2e4); a falloff width in (0, 180] degrees.
void ReadShafts(const Json& lighting, Validator& check, ShaftsSettings& shafts) {
    const Json* section = check.Section(lighting, "lighting", "shafts", kShaftsKeys);
    if (!section) return;
    shafts.on = true;
    if (const Json* v = Validator::Find(*section, "shells")) {
        if (auto n = check.Integer(*v, "lighting.shafts.shells", 1, kMaxShafts)) shafts.shells = uint32_t(*n);
    }
    if (const Json* v = Validator::Find(*section, "extinction")) {
        if (auto d = check.Number(*v, "lighting.shafts.extinction", Range{.lo = 0, .loOpen = true, .hi = 1}))
            shafts.extinction = *d;
    }
    if (const Json* v = Validator::Find(*section, "g")) {
        if (auto d = check.Number(*v, "lighting.shafts.g", Range{.lo = -0.99, .hi = 0.99})) shafts.g = *d;
    }
    if (const Json* v = Validator::Find(*section, "falloff_deg")) {
        if (auto d = check.Number(*v, "lighting.shafts.falloff_deg", Range{.lo = 0, .loOpen = true, .hi = 180}))
            shafts.falloffDeg = *d;
    }
}

void ReadCityGlow(const Json& lighting, Validator& check, CityGlowSettings& glow) {
    const Json* section = check.Section(lighting, "lighting", "city_glow", kCityGlowKeys);
    if (!section) return;
    glow.on = true;
    if (const Json* v = Validator::Find(*section, "color")) {
        if (auto a = check.Numbers<3>(*v, "lighting.city_glow.color", kGlowValue)) glow.color = *a;
    }
    if (const Json* v = Validator::Find(*section, "fade")) {
        if (auto d = check.Number(*v, "lighting.city_glow.fade", kGlowValue)) glow.fade = *d;
    }
    const std::string field = "lighting.city_glow.blobs";
    const Json* list = Validator::Find(*section, "blobs");
    if (!list) {
        check.Fail(field, "required field is missing (1 to " + std::to_string(kMaxGlowBlobs) + " blobs)");
        return;
    }
    if (!list->is_array() || list->empty() || list->size() > kMaxGlowBlobs) {
        check.Fail(field, "expected an array of 1 to " + std::to_string(kMaxGlowBlobs) +
                              " {\"center\", \"radius\", \"strength\"} objects, got " + Describe(*list));
        return;
    }
    for (size_t n = 0; n < list->size(); ++n) {
        const std::string bf = IndexField(field, n);
        const Json& item = (*list)[n];
        if (!item.is_object()) {
            check.Fail(bf, "expected a blob object, got " + Describe(item));
            continue;
        }
        check.CheckKeys(item, bf, kGlowBlobKeys);
        CityGlowSettings::Blob blob;
        if (const Json* v = Validator::Find(item, "center")) {
            if (auto a = check.Numbers<2>(*v, JoinField(bf, "center"), kGlowCenter)) blob.center = *a;
        } else {
            check.Fail(JoinField(bf, "center"), "required field is missing");
        }
        if (const Json* v = Validator::Find(item, "radius")) {
            if (auto d = check.Number(*v, JoinField(bf, "radius"), kGlowRadius)) blob.radius = *d;
        }
        if (const Json* v = Validator::Find(item, "strength")) {
            if (auto d = check.Number(*v, JoinField(bf, "strength"), kGlowValue)) blob.strength = *d;
        }
        glow.blobs.push_back(blob);
    }
}
constexpr std::string_view kLightningKeys[] = {"enabled", "position", "color", "intensity", "radius", "flash"};
constexpr std::string_view kFlashKeys[] = {"start", "steps"};

}  // namespace

void ReadLighting(const Json& root, Validator& check, LightingSettings& lighting) {
    const Json* section = check.Section(root, "", "lighting", kLightingKeys);
    if (!section) return;
    if (const Json* v = Validator::Find(*section, "ambient")) {
        if (auto a = check.Numbers<3>(*v, "lighting.ambient", kSingleNonNegative)) lighting.ambient = *a;
    }
    if (const Json* v = Validator::Find(*section, "background")) {
        if (auto a = check.Numbers<3>(*v, "lighting.background", kSingleNonNegative)) lighting.background = *a;
    }
    ReadCityGlow(*section, check, lighting.cityGlow);
    ReadEyeScattering(*section, check, lighting.eyeScattering);
    ReadSky(*section, check, lighting.sky);
    ReadOctaves(*section, check, lighting.octaves);
    ReadShafts(*section, check, lighting.shafts);
}

void ReadLightning(const Json& root, Validator& check, LightningSettings& lightning) {
    const Json* section = check.Section(root, "", "lightning", kLightningKeys);
    if (!section) return;
    lightning.enabled = true;  // the section switches it on unless "enabled": false
    auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
    if (const Json* v = find("enabled")) {
        if (auto b = check.Boolean(*v, "lightning.enabled")) lightning.enabled = *b;
    }
    if (const Json* v = find("position")) {
        if (auto a = check.Numbers<3>(*v, "lightning.position", Range{.lo = -kMaxSingle, .hi = kMaxSingle}))
            lightning.position = *a;
    } else if (lightning.enabled) {
        check.Fail("lightning.position", "required field is missing");
    }
    if (const Json* v = find("color")) {
        if (auto a = check.Numbers<3>(*v, "lightning.color", kSingleNonNegative)) lightning.color = *a;
    }
    if (const Json* v = find("intensity")) {
        if (auto d = check.Number(*v, "lightning.intensity", kSingleNonNegative)) lightning.intensity = *d;
    }
    if (const Json* v = find("radius")) {
        // r0^2 must stay a normal float: 1e-15 m squared is still far above FLT_MIN.
        if (auto d = check.Number(*v, "lightning.radius", Range{.lo = 1e-15, .hi = 1e15})) lightning.radius = *d;
    }
    // The light's radiance in float: colour * intensity (radiance * m^2, as the kernel holds it), and
    // colour * intensity / r0^2, the most it reaches (at the guard radius: the falloff is 1 / max(D^2, r0^2)), each
    // at most the sun's bound 1e30. The light then adds at most 1e30 * 2^19.5 per sample (every P^ is at most
    // 2^19.5, core/math/Shading.h kMaxPhasePeak), as the sun does; the sum over a ray stays finite (the derivation is
    // ReadSun's). Colour 1e30 times intensity 1e30 was inf in float and made pixels inf on every backend.
    if (lightning.enabled) {
        const double brightest =
            std::max({lightning.color[0], lightning.color[1], lightning.color[2]}) * lightning.intensity;
        const double atGuard = brightest / (lightning.radius * lightning.radius);
        if (brightest > kMaxSingle)
            check.Fail("lightning.intensity",
                       "color * intensity (the light's radiance at 1 m) must be at most 1e+30 in "
                       "each channel, got " +
                           FormatNumber(brightest));
        else if (atGuard > kMaxSingle)
            check.Fail("lightning.radius",
                       "color * intensity / radius^2 (the light's radiance at its guard radius, the "
                       "most it reaches) must be at most 1e+30 in each channel, got " +
                           FormatNumber(atGuard));
    }
    if (const Json* flash = check.Section(*section, "lightning", "flash", kFlashKeys)) {
        if (const Json* v = Validator::Find(*flash, "start")) {
            if (auto n = check.Integer(*v, "lightning.flash.start", 0, kU32Max)) lightning.flashStart = uint32_t(*n);
        }
        if (const Json* v = Validator::Find(*flash, "steps")) {
            if (auto n = check.Integer(*v, "lightning.flash.steps", 1, kU32Max)) lightning.flashSteps = uint32_t(*n);
        }
    }
}

}  // namespace cb::scene_io
