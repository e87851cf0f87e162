// Validation of a scene document: typed reads that report every problem as one
// "label: field: reason" line, and the --set overrides applied before them.
// Internal to core (see core/base/JsonDom.h).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/JsonDom.h"
#include "core/base/ShownText.h"
#include "core/scene/Scene.h"
#include "core/scene/SceneNames.h"

namespace cb::scene_io {

// Shortest text that reads back as the same double ("0.35", "400", "100000", "1e+20", "inf").
std::string FormatNumber(double value);

// A JSON value as it appears in an error: strings as QuoteShown shows them, control characters escaped, long
// values cut short.
std::string Describe(const Json& value);

// `text` in double quotes, as errors show names; the same as QuoteShown, since some names come from the file.
std::string Quote(std::string_view text);

// Untrusted text in double quotes, safe to print (core/base/ShownText.h).
using cb::QuoteShown;
using cb::ShownText;

// The rule for names that become a path component (the scene's out/<name>, frame files named after cameras).
inline constexpr size_t kMaxPathNameLength = 64;
inline constexpr std::string_view kPathNameRule =
    "must be 1 to 64 of the characters A-Z a-z 0-9 . _ - and not start with '.'";

// True when `name` follows kPathNameRule: never "", ".", "..", a separator or a hidden file.
bool IsPathName(std::string_view name);

// " (did you mean "x"?)" when one known name is close to `name` (or extends it), else ""; always "" for a name
// longer than 64 characters, so a huge key costs no quadratic edit distance.
std::string Suggestion(std::string_view name, std::span<const std::string_view> known);

// Collects error lines "label: field: reason" and reads typed values out of the document.
// Each read returns nullopt after reporting why, so callers keep their default and go on.
class Validator {
  public:
    explicit Validator(std::string label) : mLabel(std::move(label)) {}

    // Marks `path` (and everything under it) as given on the command line.
    void MarkOverridden(std::string path) { mOverridden.push_back(std::move(path)); }

    // Adds one error line; fields under an override (--set, --vary) get " (set on the command line)". Each part of
    // `field` is shown as QuoteShown shows text (unquoted): keys come from the file.
    void Fail(std::string_view field, std::string_view reason);

    // An error with no field (malformed JSON, unreadable file).
    void FailWhole(std::string_view reason) { mErrors.push_back(mLabel + ": " + std::string(reason)); }

    size_t ErrorCount() const { return mErrors.size(); }

    // All error lines, joined by newlines.
    std::string Message() const;

    // Reports every key of `object` that is not in `known`.
    void CheckKeys(const Json& object, std::string_view field, std::span<const std::string_view> known);

    // The member `key` of `object`, or nullptr when absent.
    static const Json* Find(const Json& object, std::string_view key);

    // The object section `key` of `parent` after checking its type and keys; nullptr when absent or wrong.
    const Json* Section(const Json& parent, std::string_view parentField, std::string_view key,
                        std::span<const std::string_view> known);

    // A whole number in [lo, hi]; integral floats such as 1e6 are accepted.
    std::optional<int64_t> Integer(const Json& value, std::string_view field, int64_t lo, int64_t hi);

    // Allowed interval of a number; infinite bounds mean "no bound", open bounds exclude the value.
    struct Range {
        double lo = -std::numeric_limits<double>::infinity();
        bool loOpen = false;
        double hi = std::numeric_limits<double>::infinity();
        bool hiOpen = false;
    };

    // A finite number inside `range`.
    std::optional<double> Number(const Json& value, std::string_view field, Range range);

    std::optional<std::string> String(const Json& value, std::string_view field);

    // A string that follows kPathNameRule, as names that become file or folder names must.
    std::optional<std::string> PathName(const Json& value, std::string_view field);

    // A JSON true or false; numbers and strings such as 1 or "true" are refused.
    std::optional<bool> Boolean(const Json& value, std::string_view field);

    // Keyframes by strictly increasing step: true when there is no previous keyframe or `step` is after it; else
    // `field` fails ("must be greater than the previous keyframe's step") and false.
    bool StepAfterPrevious(std::string_view field, std::optional<uint32_t> previous, uint32_t step);

    // One of the names of `options` (case-sensitive), mapped to its value.
    template <typename T, size_t N>
    std::optional<T> Choice(const Json& value, std::string_view field, const std::array<NamedValue<T>, N>& options) {
        if (value.is_string()) {
            if (std::optional<T> result = ValueNamed(options, value.get_ref<const std::string&>())) return result;
        }
        const std::array<std::string_view, N> names = NamesOf(options);
        FailChoice(value, field, names);
        return std::nullopt;
    }

    // A whole number from a short list; `allowedText` reads e.g. "1, 2 or 4".
    std::optional<int64_t> IntegerChoice(const Json& value, std::string_view field, std::span<const int64_t> allowed,
                                         std::string_view allowedText);

    // An array of exactly N numbers, each inside `range`.
    template <size_t N>
    std::optional<std::array<double, N>> Numbers(const Json& value, std::string_view field, Range range) {
        if (!value.is_array() || value.size() != N) {
            Fail(field, "expected an array of " + std::to_string(N) + " numbers, got " + Describe(value));
            return std::nullopt;
        }
        std::array<double, N> result{};
        bool ok = true;
        for (size_t i = 0; i < N; ++i) {
            auto d = Number(value[i], IndexField(field, i), range);
            if (d) result[i] = *d;
            ok = ok && d.has_value();
        }
        return ok ? std::optional(result) : std::nullopt;
    }

    // An array of exactly N integers, each in [lo, hi].
    template <size_t N>
    std::optional<std::array<int64_t, N>> Integers(const Json& value, std::string_view field, int64_t lo, int64_t hi) {
        if (!value.is_array() || value.size() != N) {
            Fail(field, "expected an array of " + std::to_string(N) + " integers, got " + Describe(value));
            return std::nullopt;
        }
        std::array<int64_t, N> result{};
        bool ok = true;
        for (size_t i = 0; i < N; ++i) {
            auto n = Integer(value[i], IndexField(field, i), lo, hi);
            if (n) result[i] = *n;
            ok = ok && n.has_value();
        }
        return ok ? std::optional(result) : std::nullopt;
    }

  private:
    // Reports `value` as none of `names` (with a suggestion when it is a near miss).
    void FailChoice(const Json& value, std::string_view field, std::span<const std::string_view> names);

    // True when `field` is an overridden path or lies under one.
    bool IsOverridden(std::string_view field) const;

    std::string mLabel;
    std::vector<std::string> mErrors;
    std::vector<std::string> mOverridden;
};

using Range = Validator::Range;
inline constexpr Range kFinite{};
inline constexpr Range kPositive{.lo = 0, .loOpen = true};
inline constexpr Range kNonNegative{.lo = 0};
inline constexpr Range kProbability{.lo = 0, .hi = 1};
// Quantities the stages compute in single precision (lengths, extinction, radiance) are at most kMaxSingle, so
// that their products with each other and with grid counts stay finite (float's largest is about 3.4e38).
inline constexpr double kMaxSingle = 1e30;
inline constexpr Range kSinglePositive{.lo = 0, .loOpen = true, .hi = kMaxSingle};
inline constexpr Range kSingleNonNegative{.lo = 0, .hi = kMaxSingle};

// Applies one --set to the document, reporting into `check`. Missing objects along
// the path are created; a value that is not JSON is taken as a string.
void ApplyOverride(Json& root, const SceneOverride& item, Validator& check);

}  // namespace cb::scene_io
