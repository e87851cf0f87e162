// Readers of the ray marcher's sections: `march` (SPEC 10) and `lightning`
// (Wang, Ji and Zhang, eq. 21). Fields, units and defaults: docs/scenes.md.
#include <algorithm>
#include <array>
#include <string_view>

#include "core/base/NamedValues.h"
#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kMarchKeys[] = {"step",   "adaptive", "jitter",   "light",    "light_steps",
                                           "powder", "epsilon",  "skipping", "exposure", "tone_map"};
constexpr std::string_view kAdaptiveKeys[] = {"enabled", "kappa", "start"};
constexpr std::string_view kPowderKeys[] = {"enabled", "c"};
constexpr std::string_view kSkippingKeys[] = {"enabled", "brick"};
constexpr std::string_view kLightningKeys[] = {"enabled", "position", "color", "intensity", "radius", "flash"};
constexpr std::string_view kFlashKeys[] = {"start", "steps"};

constexpr std::array<NamedValue<MarchLightSource>, 2> kMarchLightNames{{
    {"shade", MarchLightSource::Shade},
    {"march", MarchLightSource::March},
}};

// The smallest step: a ray across a 16384-voxel box then takes about 1.6e6 samples, not unbounded work.
constexpr double kMinMarchStep = 0.01;

}  // namespace

void ReadMarch(const Json& root, Validator& check, const StageSet& stages, MarchSettings& march) {
    const Json* section = check.Section(root, "", "march", kMarchKeys);
    if (section) {
        auto find = [&](std::string_view key) { return Validator::Find(*section, key); };
        if (const Json* v = find("step")) {
            if (auto d = check.Number(*v, "march.step", Range{.lo = kMinMarchStep, .hi = 1e6})) march.step = *d;
        }
        if (const Json* adaptive = check.Section(*section, "march", "adaptive", kAdaptiveKeys)) {
            if (const Json* v = Validator::Find(*adaptive, "enabled")) {
                if (auto b = check.Boolean(*v, "march.adaptive.enabled")) march.adaptive = *b;
            }
            if (const Json* v = Validator::Find(*adaptive, "kappa")) {
                if (auto d = check.Number(*v, "march.adaptive.kappa", Range{.lo = 0, .hi = 1e6})) march.kappa = *d;
            }
            if (const Json* v = Validator::Find(*adaptive, "start")) {
                if (auto d = check.Number(*v, "march.adaptive.start", kSingleNonNegative)) march.adaptiveStart = *d;
            }
        }
        if (const Json* v = find("jitter")) {
            if (auto b = check.Boolean(*v, "march.jitter")) march.jitter = *b;
        }
        if (const Json* v = find("light")) {
            if (auto kind = check.Choice(*v, "march.light", kMarchLightNames)) march.light = *kind;
        }
        if (const Json* v = find("light_steps")) {
            if (auto n = check.Integer(*v, "march.light_steps", 1, 4096)) march.lightSteps = uint32_t(*n);
        }
        if (const Json* powder = check.Section(*section, "march", "powder", kPowderKeys)) {
            if (const Json* v = Validator::Find(*powder, "enabled")) {
                if (auto b = check.Boolean(*v, "march.powder.enabled")) march.powder = *b;
            }
            if (const Json* v = Validator::Find(*powder, "c")) {
                if (auto d = check.Number(*v, "march.powder.c", Range{.lo = 0, .hi = 1000})) march.powderC = *d;
            }
        }
        if (const Json* v = find("epsilon")) {
            if (auto d = check.Number(*v, "march.epsilon", Range{.lo = 0, .hi = 1, .hiOpen = true})) march.epsilon = *d;
        }
        if (const Json* skipping = check.Section(*section, "march", "skipping", kSkippingKeys)) {
            if (const Json* v = Validator::Find(*skipping, "enabled")) {
                if (auto b = check.Boolean(*v, "march.skipping.enabled")) march.skipping = *b;
            }
            if (const Json* v = Validator::Find(*skipping, "brick")) {
                if (auto n = check.Integer(*v, "march.skipping.brick", 1, 1024)) march.brick = uint32_t(*n);
            }
        }
        if (const Json* v = find("exposure")) {
            if (auto d = check.Number(*v, "march.exposure", kSinglePositive)) march.exposure = *d;
        }
        if (const Json* v = find("tone_map")) {
            if (auto b = check.Boolean(*v, "march.tone_map")) march.toneMap = *b;
        }
    }
    // The default light source reads T, which only the shade stage writes.
    if (stages.Has(Stage::RenderMarch) && march.light == MarchLightSource::Shade && !stages.Has(Stage::Shade))
        check.Fail("march.light",
                   "\"shade\" needs stage \"shade\" (add it to stages, or set march.light to \"march\")");
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
