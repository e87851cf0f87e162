#include "core/scene/SceneValidator.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include "core/base/NamedValues.h"

namespace cb::scene_io {

std::string FormatNumber(double value) {
    if (std::isnan(value)) return "nan";
    if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
    char buffer[64];
    // Whole numbers below 1e15 are written out ("100000", not the shorter "1e+05").
    const bool whole = value == std::floor(value) && std::fabs(value) < 1e15;
    auto [end, ec] = whole ? std::to_chars(buffer, buffer + sizeof(buffer), value, std::chars_format::fixed)
                           : std::to_chars(buffer, buffer + sizeof(buffer), value);
    if (ec != std::errc()) return "?";
    return std::string(buffer, end);
}

std::string Describe(const Json& value) {
    if (value.is_string()) return QuoteShown(value.get_ref<const std::string&>());
    std::string text;
    if (value.is_number_float()) {
        text = FormatNumber(value.get<double>());
    } else {
        // ensure_ascii: control characters (C0, DEL, C1) inside arrays and objects come out as \u00XX.
        text = value.dump(-1, ' ', true, Json::error_handler_t::replace);
    }
    if (text.size() > kMaxShownChars) text = text.substr(0, kMaxShownChars - 3) + "...";
    return text;
}

std::string Quote(std::string_view text) { return QuoteShown(text); }

namespace {

// A dotted field path safe to print: each part between dots as ShownText shows it (keys come from the file).
std::string ShownField(std::string_view field) {
    std::string shown;
    for (size_t start = 0;;) {
        const size_t dot = field.find('.', start);
        shown +=
            ShownText(field.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start), false);
        if (dot == std::string_view::npos) return shown;
        shown += '.';
        start = dot + 1;
    }
}

}  // namespace

bool IsPathName(std::string_view name) {
    if (name.empty() || name.size() > kMaxPathNameLength || name.front() == '.') return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
               c == '-';
    });
}

std::string Suggestion(std::string_view name, std::span<const std::string_view> known) {
    const std::string_view best = ClosestName(name, known);
    return best.empty() ? "" : " (did you mean " + Quote(best) + "?)";
}

// ---- Validator ------------------------------------------------------------------------------------------------

void Validator::Fail(std::string_view field, std::string_view reason) {
    std::string line = mLabel + ": " + ShownField(field) + ": " + std::string(reason);
    if (IsOverridden(field)) line += " (set on the command line)";
    mErrors.push_back(std::move(line));
}

std::string Validator::Message() const {
    std::string message;
    for (const std::string& line : mErrors) {
        if (!message.empty()) message += '\n';
        message += line;
    }
    return message;
}

void Validator::CheckKeys(const Json& object, std::string_view field, std::span<const std::string_view> known) {
    for (const auto& [key, value] : object.items()) {
        if (std::find(known.begin(), known.end(), key) == known.end())
            Fail(JoinField(field, key), "unknown field" + Suggestion(key, known));
    }
}

const Json* Validator::Find(const Json& object, std::string_view key) {
    auto it = object.find(std::string(key));
    return it == object.end() ? nullptr : &*it;
}

const Json* Validator::Section(const Json& parent, std::string_view parentField, std::string_view key,
                               std::span<const std::string_view> known) {
    const Json* section = Find(parent, key);
    if (!section) return nullptr;
    const std::string field = JoinField(parentField, key);
    if (!section->is_object()) {
        Fail(field, "expected an object, got " + Describe(*section));
        return nullptr;
    }
    CheckKeys(*section, field, known);
    return section;
}

std::optional<int64_t> Validator::Integer(const Json& value, std::string_view field, int64_t lo, int64_t hi) {
    int64_t result = 0;
    bool inRange = true;
    if (value.is_number_unsigned()) {
        const uint64_t u = value.get<uint64_t>();
        inRange = u <= uint64_t(std::numeric_limits<int64_t>::max());
        result = inRange ? int64_t(u) : 0;
    } else if (value.is_number_integer()) {
        result = value.get<int64_t>();
    } else if (value.is_number_float()) {
        const double d = value.get<double>();
        if (!std::isfinite(d)) {
            Fail(field, "must be a finite integer, got " + Describe(value));
            return std::nullopt;
        }
        if (d != std::floor(d)) {
            Fail(field, "expected an integer, got " + Describe(value));
            return std::nullopt;
        }
        inRange = d >= -9.2e18 && d <= 9.2e18;
        result = inRange ? int64_t(d) : 0;
    } else {
        Fail(field, "expected an integer, got " + Describe(value));
        return std::nullopt;
    }
    if (!inRange || result < lo || result > hi) {
        Fail(field, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + Describe(value));
        return std::nullopt;
    }
    return result;
}

std::optional<double> Validator::Number(const Json& value, std::string_view field, Range range) {
    if (!value.is_number()) {
        Fail(field, "expected a number, got " + Describe(value));
        return std::nullopt;
    }
    const double d = value.get<double>();
    if (!std::isfinite(d)) {
        Fail(field, "must be a finite number, got " + Describe(value));
        return std::nullopt;
    }
    const bool loOk = range.loOpen ? d > range.lo : d >= range.lo;
    const bool hiOk = range.hiOpen ? d < range.hi : d <= range.hi;
    if (loOk && hiOk) return d;
    std::string reason;
    if (std::isinf(range.hi)) {
        reason = std::string("must be ") + (range.loOpen ? "> " : ">= ") + FormatNumber(range.lo);
    } else if (std::isinf(range.lo)) {
        reason = std::string("must be ") + (range.hiOpen ? "< " : "<= ") + FormatNumber(range.hi);
    } else {
        reason = std::string("must be in ") + (range.loOpen ? "(" : "[") + FormatNumber(range.lo) + ", " +
                 FormatNumber(range.hi) + (range.hiOpen ? ")" : "]");
    }
    Fail(field, reason + ", got " + Describe(value));
    return std::nullopt;
}

std::optional<std::string> Validator::String(const Json& value, std::string_view field) {
    if (!value.is_string()) {
        Fail(field, "expected a string, got " + Describe(value));
        return std::nullopt;
    }
    return value.get<std::string>();
}

std::optional<std::string> Validator::PathName(const Json& value, std::string_view field) {
    if (!value.is_string()) {
        Fail(field, "expected a string, got " + Describe(value));
        return std::nullopt;
    }
    const std::string& name = value.get_ref<const std::string&>();
    if (!IsPathName(name)) {
        Fail(field, std::string(kPathNameRule) + ", got " + QuoteShown(name));
        return std::nullopt;
    }
    return name;
}

bool Validator::StepAfterPrevious(std::string_view field, std::optional<uint32_t> previous, uint32_t step) {
    if (!previous || step > *previous) return true;
    Fail(field, "must be greater than the previous keyframe's step (" + std::to_string(*previous) + "), got " +
                    std::to_string(step));
    return false;
}

std::optional<bool> Validator::Boolean(const Json& value, std::string_view field) {
    if (!value.is_boolean()) {
        Fail(field, "expected true or false, got " + Describe(value));
        return std::nullopt;
    }
    return value.get<bool>();
}

void Validator::FailChoice(const Json& value, std::string_view field, std::span<const std::string_view> names) {
    std::string list;
    for (size_t i = 0; i < names.size(); ++i) list += (i == 0 ? "" : ", ") + Quote(names[i]);
    std::string reason = "must be one of " + list + ", got " + Describe(value);
    if (value.is_string()) reason += Suggestion(value.get_ref<const std::string&>(), names);
    Fail(field, reason);
}

std::optional<int64_t> Validator::IntegerChoice(const Json& value, std::string_view field,
                                                std::span<const int64_t> allowed, std::string_view allowedText) {
    // Whole numbers beyond int64 are simply not in the list (rather than outside int64's range).
    const bool huge =
        (value.is_number_unsigned() && value.get<uint64_t>() > uint64_t(std::numeric_limits<int64_t>::max())) ||
        (value.is_number_float() && std::isfinite(value.get<double>()) &&
         value.get<double>() == std::floor(value.get<double>()) && std::fabs(value.get<double>()) > 9.2e18);
    std::optional<int64_t> n;
    if (!huge) {
        n = Integer(value, field, std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max());
        if (!n) return std::nullopt;  // not an integer: already reported
        if (std::find(allowed.begin(), allowed.end(), *n) != allowed.end()) return n;
    }
    Fail(field, "must be " + std::string(allowedText) + ", got " + Describe(value));
    return std::nullopt;
}

bool Validator::IsOverridden(std::string_view field) const {
    for (const std::string& path : mOverridden) {
        if (!field.starts_with(path)) continue;
        if (field.size() == path.size() || field[path.size()] == '.' || field[path.size()] == '[') return true;
    }
    return false;
}

// ---- --set ----------------------------------------------------------------------------------------------------

void ApplyOverride(Json& root, const SceneOverride& item, Validator& check) {
    const std::string where = "--set " + item.path;
    std::vector<std::string> keys;
    for (size_t start = 0;;) {
        const size_t dot = item.path.find('.', start);
        keys.push_back(item.path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    for (const std::string& key : keys) {
        if (key.empty()) {
            check.Fail(where, "expected a dotted field path such as ca.seed");
            return;
        }
    }

    // The value is JSON text; anything that does not parse is taken as a string.
    JsonDom parsed = ParseJsonDom(item.value);
    if (parsed.failure && parsed.failure->IsNumberOverflow()) {
        // Number overflow (1e999) is a number, not a bare word: refuse it rather than take it as a string.
        check.MarkOverridden(item.path);
        check.Fail(item.path, "the number " + ShownText(parsed.failure->token) + " is out of range (not finite)");
        return;
    }
    if (parsed.failure && parsed.failure->IsTooDeep()) {
        check.MarkOverridden(item.path);
        check.Fail(item.path, "nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
        return;
    }
    Json value = parsed.failure ? Json(item.value) : std::move(parsed.root);

    Json* node = &root;
    std::string prefix;
    for (size_t i = 0; i + 1 < keys.size(); ++i) {
        prefix = JoinField(prefix, keys[i]);
        auto it = node->find(keys[i]);
        if (it == node->end()) {
            // The object is the command line's, so an error on it (an unknown section) says so.
            check.MarkOverridden(prefix);
            node = &((*node)[keys[i]] = Json::object());
        } else if (it->is_object()) {
            node = &*it;
        } else {
            check.Fail(where, Quote(prefix) + " is not an object");
            return;
        }
    }
    (*node)[keys.back()] = std::move(value);
    check.MarkOverridden(item.path);
    if (!parsed.failure) {
        for (const std::string& duplicate : parsed.duplicates)
            check.Fail(JoinField(item.path, duplicate), "duplicate field");
    }
}

}  // namespace cb::scene_io
