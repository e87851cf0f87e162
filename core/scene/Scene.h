// A scene: what to simulate and which stages to run. Loaded from JSON by
// LoadScene() (core/plan/SceneLoad.h), which validates every field before any work is done. The fields,
// their units and defaults are documented in docs/scenes.md.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/base/Error.h"
#include "core/math/Camera.h"
#include "core/math/Grid.h"
#include "core/math/Light.h"
#include "core/math/NoiseSettings.h"
#include "core/math/Shading.h"
#include "core/math/Shafts.h"
#include "core/scene/Stage.h"
#include "core/stages/ca/CaTypes.h"
#include "core/stages/density/DensityTypes.h"
#include "core/stages/noise/NoiseTypes.h"
#include "core/stages/region/RegionTypes.h"
#include "core/stages/render_layers/RenderLayersTypes.h"
#include "core/stages/render_march/RenderMarchTypes.h"
#include "core/stages/render_splat/RenderSplatTypes.h"
#include "core/stages/shade/ShadeTypes.h"
#include "core/stages/shadow/ShadowTypes.h"
#include "core/stages/smooth/SmoothTypes.h"

namespace cb {

struct GridSettings {
    Extent3 size{64, 16, 64};
    double voxelSize = 50.0;                // metres per voxel edge (h)
    std::array<double, 3> origin{0, 0, 0};  // world position of voxel corner (0,0,0), metres
    // The density and the light repeat in x and y with the grid's period (SPEC 15); renderers that honour it
    // read (x mod nx h, y mod ny h, z). Off: outside the box is empty.
    bool tiling = false;
};

// One keyframe of a sun path: the sun's angles at a step.
struct SunKeyframe {
    uint32_t step = 0;
    double elevationDeg = 0, azimuthDeg = 0;
    bool operator==(const SunKeyframe&) const = default;
};

// The sun (SPEC 0): direction from elevation and azimuth, and its radiance.
// It may move (Fizimayer's thesis, section 1.3.2): along keyframes, or at a constant
// angular speed. Either way it is evaluated once per step (ElevationAt,
// AzimuthAt); the frames between two steps see step t's sun (docs/pipeline.md,
// "The real-time loop").
struct SunSettings {
    double elevationDeg = 40;                     // above the horizon, degrees (step 0's, with a path)
    double azimuthDeg = 30;                       // from +x toward +y, degrees (step 0's, with a path)
    std::array<double, 3> color{1.0, 0.96, 0.9};  // linear RGB
    double intensity = 1.0;                       // multiplies color
    // Keyframes in increasing step order; empty: no path. Between two
    // keyframes both angles are interpolated linearly in the step; before the
    // first and after the last the sun holds that keyframe's angles.
    std::vector<SunKeyframe> path;
    // Degrees per step added to elevationDeg and azimuthDeg (no path).
    double elevationSpeedDeg = 0, azimuthSpeedDeg = 0;

    double ElevationAt(uint32_t step) const;
    double AzimuthAt(uint32_t step) const;
    // Unit vector toward the sun at `step`.
    Vec3 DirectionAt(uint32_t step) const {
        constexpr double kDeg = 3.14159265358979323846 / 180.0;
        return SunDirection(ElevationAt(step) * kDeg, AzimuthAt(step) * kDeg);
    }
    // Unit vector toward the sun at step 0 (the fixed sun's direction).
    Vec3 Direction() const { return DirectionAt(0); }
    // True when the direction may differ between steps (a path of two or more
    // keyframes, or a non-zero speed).
    bool Moves() const { return path.size() > 1 || elevationSpeedDeg != 0 || azimuthSpeedDeg != 0; }
    // color * intensity.
    Vec3 Radiance() const {
        return {float(color[0] * intensity), float(color[1] * intensity), float(color[2] * intensity)};
    }
};

// City glow (Wang, Ji and Zhang, eq. 20): the light of a city below lighting the clouds from underneath,
// glow = g(x, y) (1 - clamp(fade dH / thickness, 0, 1)) times `color`, with g a sum of Gaussian blobs
// (section `lighting.city_glow`; docs/pipeline.md, "City glow").
struct CityGlowSettings {
    // One blob of g: strength exp(-|(x, y) - center|^2 / (2 radius^2)).
    struct Blob {
        std::array<double, 2> center{0, 0};  // world x, y, metres
        double radius = 1000;                // sigma, metres
        double strength = 1;
    };
    bool on = false;                           // the section is present
    std::array<double, 3> color{1, 0.6, 0.3};  // linear RGB radiance where g = 1 at the cloud base
    double fade = 1;                           // f_c: the glow is gone at dH = thickness / fade
    std::vector<Blob> blobs;                   // 1 to kMaxGlowBlobs (core/math/Light.h)
};

// Eye scattering (Wang, Ji and Zhang, eq. 17): the sun's light scattered toward an eye that looks near the sun, a
// fast stand-in for the phase function's forward peak, sun T I_e with
// I_e = intensity max(0, (d . s - cos cone) / (1 - cos cone)) (height_gain clamp(dH / thickness, 0, 1) + 1)
// (section `lighting.eye_scattering`; docs/pipeline.md, "Eye scattering").
struct EyeScatteringSettings {
    bool on = false;        // the section is present
    double intensity = 1;   // I_e0
    double coneDeg = 10;    // phi, degrees: no eye scattering farther than this from the sun
    double heightGain = 0;  // f_e: how much it grows toward the cloud top
    // Wang's model: the renderers light the sun's (and the point light's) term with no phase function and the eye
    // scattering carries the forward peak; the exact reference keeps the scene's phase function.
    bool replacesPhase = false;
};

// Skylight (Wang, Ji and Zhang, section 3.3): a second directional light, fixed, above the horizon, lit through its
// own attenuation T_sky (stage shade_sky, which runs iff the section is present): colour term
// sky T_sky P^(s_sky . d) (section `lighting.sky`; docs/pipeline.md, "Skylight").
struct SkyLightSettings {
    bool on = false;                             // the section is present
    double elevationDeg = 20;                    // above the horizon, degrees, in (0, 90]
    double azimuthDeg = 0;                       // from +x toward +y, degrees
    std::array<double, 3> color{0.5, 0.6, 0.9};  // linear RGB
    double intensity = 1.0;                      // multiplies color

    // Unit vector toward the sky light.
    Vec3 Direction() const {
        constexpr double kDeg = 3.14159265358979323846 / 180.0;
        return SunDirection(elevationDeg * kDeg, azimuthDeg * kDeg);
    }
    // color * intensity.
    Vec3 Radiance() const {
        return {float(color[0] * intensity), float(color[1] * intensity), float(color[2] * intensity)};
    }
};

// Multiple scattering as octaves of the sun's single scattering (section `lighting.octaves`; core/math/Light.h
// LightTerms): octave i < count scales the extinction toward the sun by attenuation^i, its light by
// contribution^i and the phase's eccentricity by eccentricity^i. count 1: single scattering.
struct OctaveSettings {
    uint32_t count = 1;
    double attenuation = 0.5, contribution = 0.5, eccentricity = 0.5;
};

struct LightingSettings {
    std::array<double, 3> ambient{0.25, 0.3, 0.38};     // linear RGB, added to every splat
    std::array<double, 3> background{0.45, 0.6, 0.85};  // linear RGB behind the clouds
    CityGlowSettings cityGlow;
    EyeScatteringSettings eyeScattering;
    SkyLightSettings sky;
    OctaveSettings octaves;
    ShaftsSettings shafts;  // shafts of light (SPEC 18), added to every renderer's frame

    // In single precision, as the renderers use them.
    Vec3 Ambient() const { return {float(ambient[0]), float(ambient[1]), float(ambient[2])}; }
    Vec3 Background() const { return {float(background[0]), float(background[1]), float(background[2])}; }
};

// A point light (Wang, Ji and Zhang, eq. 21) that flashes over a window of steps (section `lightning`);
// every renderer takes it through its light terms (core/pipeline/LightTerms.h).
struct LightningSettings {
    bool enabled = false;
    std::array<double, 3> position{0, 0, 0};  // world, metres
    std::array<double, 3> color{0.8, 0.85, 1.0};
    double intensity = 1e6;                   // radiance * metres^2
    double radius = 50;                       // r0, metres: the 1/D^2 law is capped at 1/r0^2
    uint32_t flashStart = 0, flashSteps = 1;  // on for steps [start, start + steps)

    bool OnAt(uint32_t step) const {
        return enabled && step >= flashStart && uint64_t(step) < uint64_t(flashStart) + flashSteps;
    }
};

// Stage `shade` (SPEC 6).

// What every renderer shares (section `render`): the image, the cameras,
// when to render and where between two steps.
struct RenderSettings {
    uint32_t width = 320, height = 240;
    double alpha = 0.5;  // interpolation between the previous and the current step
    // Frames rendered per render step (Fizimayer's thesis, section 6.3). 1: one frame
    // at `alpha`; F > 1: frames f = 0..F-1 at alpha = (f + 1) / F.
    uint32_t framesPerStep = 1;
    // Time-slicing (SPEC 13, Fizimayer's thesis, sections 7.1 and 8.1.2): 0 computes a
    // step all at once; s > 0 spreads the next step's stages over this step's
    // frames, s slices of one stage per frame (docs/pipeline.md). A step then
    // draws max(framesPerStep, the frames its shares take) frames.
    uint32_t slicesPerFrame = 0;
    uint32_t everySteps = 0;              // render every N steps after warm-up (and the last); 0 = last step only
    std::vector<CameraSettings> cameras;  // at least one when a renderer runs
    // The ground plane z = origin_z under the clouds, lit through G (render.ground;
    // docs/pipeline.md, "The ground in the frame"). Needs the stage `shadow`.
    struct Ground {
        bool on = false;                              // absent from the scene: off
        std::array<double, 3> albedo{0.3, 0.3, 0.3};  // linear RGB reflectance, each in [0, 1]
    } ground;

    // The interpolation weight of frame `frame` (0-based) of a render step of
    // `frames` frames (0: framesPerStep). One frame without time-slicing draws
    // at the fixed `alpha`; otherwise frames run alpha = (frame + 1) / frames.
    float FrameAlpha(uint32_t frame, uint32_t frames = 0) const {
        if (frames == 0) frames = framesPerStep;
        if (frames <= 1 && slicesPerFrame == 0) return float(alpha);
        return float(double(frame + 1) / double(frames > 0 ? frames : 1));
    }
};

struct Scene {
    std::string name;
    std::string path;  // file it was read from ("" for built-in)
    GridSettings grid;
    uint32_t steps = 20;
    uint32_t warmupSteps = 0;  // leading steps left out of timing and cover statistics
    StageSet stages;
    CaSettings ca;
    EllipsoidSettings ellipsoids;
    SmoothSettings smooth;
    DensitySettings density;
    SunSettings sun;
    LightingSettings lighting;
    PhaseParams phase;  // used by shade (scattering) and render_splat
    ShadeSettings shade;
    ShadowSettings shadow;
    RenderSettings render;
    SplatSettings splat;
    MarchSettings march;          // stage render_march (section `march`)
    LightningSettings lightning;  // the point light (section `lightning`)
    NoiseSettings noise;          // stage `noise` (SPEC 10a)
    LayersSettings layers;        // stage render_layers (section `layers`)
    // What the enabled renderers ask of the stages upstream, decided when the scene is loaded (core/plan/SceneLoad.cpp,
    // from the renderers' descriptors), not read from the file: shade reads this, not a renderer's section.
    struct RendererNeeds {
        bool shadeOnce = false;  // T shaded once, for step 0's sun, and relit per frame (a renderer relights)
    } needs;
};

// One --set PATH=VALUE override, applied to the JSON before validation.
struct SceneOverride {
    std::string path;   // dotted, e.g. "ca.seed" or "grid.size"
    std::string value;  // JSON text; a bare word is taken as a string
};

}  // namespace cb
