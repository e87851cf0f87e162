// The names scene files use for the shading enums (docs/scenes.md), published
// once: the scene reader parses them, the harness writes them back (--set,
// --vary), and error messages list them in table order.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

#include "core/Shading.h"

namespace cb {

// One spelling of an enum value.
template <typename Enum>
struct NamedValue {
    std::string_view name;
    Enum value;
};

// Each table holds every value of its enum exactly once, in the order errors and help list them.
inline constexpr std::array<NamedValue<PhaseKind>, 3> kPhaseKindNames{{
    {"none", PhaseKind::None},
    {"henyey-greenstein", PhaseKind::HenyeyGreenstein},
    {"cornette-shanks", PhaseKind::CornetteShanks},
}};
inline constexpr std::array<NamedValue<AttenuationKind>, 2> kAttenuationKindNames{{
    {"beer", AttenuationKind::Beer},
    {"thesis", AttenuationKind::Thesis},
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

// The value spelled `name` (case-sensitive), or nullopt.
template <typename Enum, size_t N>
constexpr std::optional<Enum> ValueNamed(const std::array<NamedValue<Enum>, N>& table, std::string_view name) {
    for (const NamedValue<Enum>& entry : table)
        if (entry.name == name) return entry.value;
    return std::nullopt;
}

// The name of `value`; "?" for a value the table lacks (none, for the tables above).
template <typename Enum, size_t N>
constexpr std::string_view NameOf(const std::array<NamedValue<Enum>, N>& table, Enum value) {
    for (const NamedValue<Enum>& entry : table)
        if (entry.value == value) return entry.name;
    return "?";
}

// The names alone, in table order.
template <typename Enum, size_t N>
constexpr std::array<std::string_view, N> NamesOf(const std::array<NamedValue<Enum>, N>& table) {
    std::array<std::string_view, N> names{};
    for (size_t i = 0; i < N; ++i) names[i] = table[i].name;
    return names;
}

constexpr std::string_view PhaseKindName(PhaseKind kind) { return NameOf(kPhaseKindNames, kind); }
constexpr std::string_view AttenuationKindName(AttenuationKind kind) { return NameOf(kAttenuationKindNames, kind); }
constexpr std::string_view SampleFilterName(SampleFilter filter) { return NameOf(kSampleFilterNames, filter); }
constexpr std::string_view StorageFormatName(StorageFormat format) { return NameOf(kStorageFormatNames, format); }

}  // namespace cb
