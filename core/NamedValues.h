// Enum <-> name tables: one spelling per value, in the order errors and help
// list them. Every table is published once, beside its enum, and used for
// parsing, for messages and for writing the value back.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace cb {

// One spelling of an enum value.
template <typename Enum>
struct NamedValue {
    std::string_view name;
    Enum value;
};

// The value spelled `name` (case-sensitive), or nullopt.
template <typename Enum, size_t N>
constexpr std::optional<Enum> ValueNamed(const std::array<NamedValue<Enum>, N>& table, std::string_view name) {
    for (const NamedValue<Enum>& entry : table)
        if (entry.name == name) return entry.value;
    return std::nullopt;
}

// The name of `value`; "?" for a value the table lacks.
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

// The names as a choice in prose: "a", "a or b", "a, b or c".
template <typename Enum, size_t N>
std::string ChoiceOf(const std::array<NamedValue<Enum>, N>& table) {
    std::string out;
    for (size_t i = 0; i < N; ++i) {
        if (i > 0) out += i + 1 == N ? " or " : ", ";
        out += table[i].name;
    }
    return out;
}

}  // namespace cb
