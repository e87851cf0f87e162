// The one list of pipeline stages (docs/contract.md sections 2-10a). Each name is also
// the timing label, the dump name and the report row, so a stage is spelled the
// same everywhere: scene files, results.json, tables and test names.
//
// CB_STAGES is the list, in the spirit of Filament's DriverAPI.inc: the enum,
// the names, the SPEC sections and kAllStages all expand from it, and
// core/pipeline/Backend.h expands the backends' entry points from CB_BACKEND_ENTRIES
// beside it. Adding a stage starts with one line here (CONTRIBUTING.md,
// "Adding a stage").
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string_view>

namespace cb {

// X(Enum, "name", "SPEC section", splat pipeline?): a stage of the splat
// pipeline (SPEC 2-8) is one every backend implements.
#define CB_STAGES(X)                                                                                 \
    X(Region, "region", "2", true)                /* ellipsoids -> uint8 region volume R */          \
    X(Ca, "ca", "3", true)                        /* cellular automaton on hum/act/cld bit fields */ \
    X(Smooth, "smooth", "4", true)                /* binomial smoothing cld -> q */                  \
    X(Density, "density", "5", true)              /* column sums D, tile/band occupancy, cover */    \
    X(Shade, "shade", "6", true)                  /* light attenuation T by inverse shear-warp */    \
    X(ShadeSky, "shade_sky", "16", false)         /* the sky light's T_sky, by shade's sweep */      \
    X(Shadow, "shadow", "7", true)                /* ground shadow G */                              \
    X(RenderSplat, "render_splat", "8", true)     /* point-sprite splatting */                       \
    X(RenderMarch, "render_march", "10", false)   /* per-pixel ray march */                          \
    X(Noise, "noise", "10a", false)               /* noise-formed density */                         \
    X(RenderLayers, "render_layers", "15", false) /* Wang's instanced horizontal layers */

enum class Stage : uint8_t {
#define CB_STAGE_ENUM(name, text, spec, splat) name,
    CB_STAGES(CB_STAGE_ENUM)
#undef CB_STAGE_ENUM
};

inline constexpr std::array kAllStages = {
#define CB_STAGE_VALUE(name, text, spec, splat) Stage::name,
    CB_STAGES(CB_STAGE_VALUE)
#undef CB_STAGE_VALUE
};
inline constexpr size_t kStageCount = kAllStages.size();

constexpr std::string_view StageName(Stage stage) {
    switch (stage) {
#define CB_STAGE_NAME(name, text, spec, splat) \
    case Stage::name:                          \
        return text;
        CB_STAGES(CB_STAGE_NAME)
#undef CB_STAGE_NAME
    }
    return "?";
}

// The section of docs/contract.md that is the stage's contract ("2" ... "10a").
constexpr std::string_view StageSpecSection(Stage stage) {
    switch (stage) {
#define CB_STAGE_SPEC(name, text, spec, splat) \
    case Stage::name:                          \
        return spec;
        CB_STAGES(CB_STAGE_SPEC)
#undef CB_STAGE_SPEC
    }
    return "?";
}

// The stages of the thesis's splat pipeline (SPEC 2-8), which every backend
// implements; render_march and noise, the ray-march path, are not among them.
constexpr bool IsSplatPipelineStage(Stage stage) {
    switch (stage) {
#define CB_STAGE_SPLAT(name, text, spec, splat) \
    case Stage::name:                           \
        return splat;
        CB_STAGES(CB_STAGE_SPLAT)
#undef CB_STAGE_SPLAT
    }
    return false;
}

constexpr std::optional<Stage> ParseStage(std::string_view name) {
    for (Stage stage : kAllStages) {
        if (StageName(stage) == name) return stage;
    }
    return std::nullopt;
}

// A small set of stages, as a bit mask over Stage.
class StageSet {
  public:
    constexpr StageSet() = default;
    constexpr StageSet(std::initializer_list<Stage> stages) {
        for (Stage s : stages) Add(s);
    }
    constexpr void Add(Stage s) { mBits |= Bit(s); }
    constexpr void Remove(Stage s) { mBits &= ~Bit(s); }
    constexpr bool Has(Stage s) const { return (mBits & Bit(s)) != 0; }
    constexpr bool Empty() const { return mBits == 0; }
    constexpr bool operator==(const StageSet&) const = default;

  private:
    static constexpr uint32_t Bit(Stage s) { return 1u << static_cast<uint32_t>(s); }
    uint32_t mBits = 0;
};
static_assert(kStageCount <= 32, "StageSet holds at most 32 stages");

}  // namespace cb
