// The names scene files use for the shading enums (docs/scenes.md), published
// once: the scene reader parses them, the harness writes them back (--set,
// --vary), and error messages list them in table order.
#pragma once

#include <array>
#include <string_view>

#include "core/base/NamedValues.h"
#include "core/math/Shading.h"

namespace cb {

// Each table holds every value of its enum exactly once, in the order errors and help list them.
inline constexpr std::array<NamedValue<PhaseKind>, 5> kPhaseKindNames{{
    {"none", PhaseKind::None},
    {"henyey-greenstein", PhaseKind::HenyeyGreenstein},
    {"cornette-shanks", PhaseKind::CornetteShanks},
    {"mie", PhaseKind::Mie},
    {"dual-lobe", PhaseKind::DualLobe},
}};
inline constexpr std::array<NamedValue<AttenuationKind>, 2> kAttenuationKindNames{{
    {"beer", AttenuationKind::Beer},
    {"thesis", AttenuationKind::Thesis},
}};
inline constexpr std::array<NamedValue<ShadowForm>, 3> kShadowFormNames{{
    {"beer", ShadowForm::Beer},
    {"thesis", ShadowForm::Thesis},
    {"wang", ShadowForm::Wang},
}};
inline constexpr std::array<NamedValue<SampleFilter>, 2> kSampleFilterNames{{
    {"bilinear", SampleFilter::Bilinear},
    {"nearest", SampleFilter::Nearest},
}};
inline constexpr std::array<NamedValue<StorageFormat>, 3> kStorageFormatNames{{
    {"fp32", StorageFormat::Fp32},
    {"fp16", StorageFormat::Fp16},
    {"unorm8", StorageFormat::Unorm8},
}};

constexpr std::string_view PhaseKindName(PhaseKind kind) { return NameOf(kPhaseKindNames, kind); }
constexpr std::string_view AttenuationKindName(AttenuationKind kind) { return NameOf(kAttenuationKindNames, kind); }
constexpr std::string_view ShadowFormName(ShadowForm form) { return NameOf(kShadowFormNames, form); }
constexpr std::string_view SampleFilterName(SampleFilter filter) { return NameOf(kSampleFilterNames, filter); }
constexpr std::string_view StorageFormatName(StorageFormat format) { return NameOf(kStorageFormatNames, format); }

}  // namespace cb
