// The one list of pipeline stages (SPEC.md sections 2-10a). Each name is also
// the timing label, the dump name and the report row, so a stage is spelled the
// same everywhere: scene files, results.json, tables and test names.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace cb {

enum class Stage : uint8_t {
    Region,       // SPEC 2: ellipsoids -> uint8 region volume R
    Ca,           // SPEC 3: cellular automaton step on hum/act/cld bit fields
    Smooth,       // SPEC 4: binomial smoothing cld -> q
    Density,      // SPEC 5: column sums D, tile/band occupancy, cloud cover
    Shade,        // SPEC 6: light attenuation T by inverse shear-warp
    Shadow,       // SPEC 7: ground shadow G
    RenderSplat,  // SPEC 8: point-sprite splatting
    RenderMarch,  // SPEC 10: per-pixel ray march
    Noise,        // SPEC 10a: noise-formed density
};

inline constexpr std::array kAllStages = {
    Stage::Region, Stage::Ca,     Stage::Smooth,      Stage::Density,     Stage::Shade,
    Stage::Shadow, Stage::RenderSplat, Stage::RenderMarch, Stage::Noise,
};

constexpr std::string_view StageName(Stage stage) {
    switch (stage) {
        case Stage::Region: return "region";
        case Stage::Ca: return "ca";
        case Stage::Smooth: return "smooth";
        case Stage::Density: return "density";
        case Stage::Shade: return "shade";
        case Stage::Shadow: return "shadow";
        case Stage::RenderSplat: return "render_splat";
        case Stage::RenderMarch: return "render_march";
        case Stage::Noise: return "noise";
    }
    return "?";
}

// The stages of the thesis's splat pipeline (SPEC 2-8), which every backend
// implements; render_march and noise are not built yet.
constexpr bool IsSplatPipelineStage(Stage stage) {
    switch (stage) {
        case Stage::Region:
        case Stage::Ca:
        case Stage::Smooth:
        case Stage::Density:
        case Stage::Shade:
        case Stage::Shadow:
        case Stage::RenderSplat: return true;
        case Stage::RenderMarch:
        case Stage::Noise: return false;
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
    constexpr void Add(Stage s) { mBits |= Bit(s); }
    constexpr bool Has(Stage s) const { return (mBits & Bit(s)) != 0; }
    constexpr bool Empty() const { return mBits == 0; }
    constexpr bool operator==(const StageSet&) const = default;

  private:
    static constexpr uint32_t Bit(Stage s) { return 1u << static_cast<uint32_t>(s); }
    uint32_t mBits = 0;
};

}  // namespace cb
