// Enum <-> name tables: one spelling per value, in the order errors and help
// list them. Every table is published once, beside its enum, and used for
// parsing, for messages and for writing the value back.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cb {

// Levenshtein distance with ASCII case ignored, for "did you mean" over names.
// Quadratic: callers bound the lengths they pass.
inline size_t EditDistance(std::string_view a, std::string_view b) {
    auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; };
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            const size_t substitute = diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
            row[j] = std::min({above + 1, row[j - 1] + 1, substitute});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// The known name `name` was most likely meant as, or "" when none is close: the one known name that `name`
// starts (3 characters or more: "fov" for "fov_deg"), else the nearest within two edits and fewer edits than
// the shorter name has letters ("cpuu", "CPU"). Names over 64 characters get none (the distance is quadratic).
template <typename Names>
std::string_view ClosestName(std::string_view name, const Names& known) {
    constexpr size_t kMaxSuggestedChars = 64;
    if (name.size() > kMaxSuggestedChars) return {};
    if (name.size() >= 3) {
        std::string_view extended;
        size_t matches = 0;
        for (std::string_view candidate : known)
            if (candidate.size() > name.size() && EditDistance(candidate.substr(0, name.size()), name) == 0) {
                extended = candidate;
                ++matches;
            }
        if (matches == 1) return extended;
    }
    std::string_view best;
    size_t bestDistance = size_t(-1);
    for (std::string_view candidate : known) {
        const size_t d = EditDistance(name, candidate);
        if (d < bestDistance) {
            bestDistance = d;
            best = candidate;
        }
    }
    if (best.empty() || bestDistance > 2 || bestDistance >= std::min(name.size(), best.size())) return {};
    return best;
}

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
