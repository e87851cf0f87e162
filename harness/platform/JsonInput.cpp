#include "harness/platform/JsonInput.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "core/base/JsonDom.h"
#include "core/base/NamedValues.h"
#include "core/base/ShownText.h"
#include "core/scene/SceneValidator.h"
#include "core/scene/Stage.h"
#include "harness/platform/Command.h"

namespace cb {
namespace schema {

struct NodeData {
    enum class Kind { Any, Boolean, Text, Number, Integer, Array, Object, Map, Either };
    Kind kind = Kind::Any;
    bool nullable = false;
    bool nonFiniteText = false;         // Number: "nan", "inf", "-inf" allowed too
    std::vector<std::string> allowed;   // Text: empty means any text
    bool pathName = false;              // Text: a name that follows kPathNameRule
    double low = 0, high = 0;           // Number, Integer
    Node element;                       // Array
    size_t minItems = 0, maxItems = 0;  // Array
    std::vector<Field> fields;          // Object
    bool open = false;                  // Object: other keys allowed
    KeyRule keys = KeyRule::Any;        // Map
    Node value;                         // Map; Either: the second choice (`element` the first)
};

namespace {

using nlohmann::json;
using Kind = NodeData::Kind;

Node Make(NodeData data) { return std::make_shared<const NodeData>(std::move(data)); }

// Shortest text that reads back as the same double ("0.5", "1e+09").
std::string FormatNumber(double value) {
    char text[64];
    const auto [end, error] = std::to_chars(text, text + sizeof text, value);
    return error == std::errc() ? std::string(text, end) : std::to_string(value);
}

// A value as an error shows it: strings quoted and escaped, containers by kind, the rest cut short.
std::string Describe(const json& value) {
    switch (value.type()) {
        case json::value_t::string:
            return QuoteShown(value.get_ref<const std::string&>());
        case json::value_t::object:
            return "an object";
        case json::value_t::array:
            return "an array";
        case json::value_t::null:
            return "null";
        default:
            return ShownText(value.dump());
    }
}

std::string_view KindName(Kind kind) {
    switch (kind) {
        case Kind::Boolean:
            return "true or false";
        case Kind::Text:
            return "a string";
        case Kind::Number:
            return "a number";
        case Kind::Integer:
            return "a whole number";
        case Kind::Array:
            return "an array";
        case Kind::Object:
        case Kind::Map:
            return "an object";
        case Kind::Any:
        case Kind::Either:
            break;
    }
    return "a value";
}

std::string Range(double low, double high) { return "[" + FormatNumber(low) + ", " + FormatNumber(high) + "]"; }

std::string List(std::span<const std::string_view> names) {
    std::string out;
    for (std::string_view name : names) out += (out.empty() ? "" : ", ") + std::string(name);
    return out;
}

std::string Suggest(std::string_view name, std::span<const std::string_view> known) {
    const std::string_view best = ClosestName(name, known);
    return best.empty() ? "" : " (did you mean " + QuoteShown(best) + "?)";
}

// Why `key` cannot be a key of a map with rule `rule`; "" when it can.
std::string KeyProblem(KeyRule rule, const std::string& key) {
    switch (rule) {
        case KeyRule::Any:
            return "";
        case KeyRule::Backend: {
            const std::span<const std::string_view> known = KnownBackends();
            if (std::ranges::find(known, key) != known.end()) return "";
            return "unknown backend " + QuoteShown(key) + Suggest(key, known) + "; known: " + List(known);
        }
        case KeyRule::Stage: {
            static const std::vector<std::string_view> known = [] {
                std::vector<std::string_view> names;
                for (Stage stage : kAllStages) names.push_back(StageName(stage));
                return names;
            }();
            if (std::ranges::find(known, key) != known.end()) return "";
            return "unknown stage " + QuoteShown(key) + Suggest(key, known) + "; known: " + List(known);
        }
        case KeyRule::PathName:
            if (scene_io::IsPathName(key)) return "";
            return QuoteShown(key) + " is not a name: " + std::string(scene_io::kPathNameRule);
    }
    return "";
}

// Whether `value` is the JSON type `s` is about, whatever else is wrong with it.
bool SameKind(const json& value, const NodeData& s) {
    switch (s.kind) {
        case Kind::Boolean:
            return value.is_boolean();
        case Kind::Text:
            return value.is_string();
        case Kind::Number:
        case Kind::Integer:
            return value.is_number();
        case Kind::Array:
            return value.is_array();
        case Kind::Object:
        case Kind::Map:
            return value.is_object();
        case Kind::Any:
        case Kind::Either:
            return true;
    }
    return false;
}

struct Checker {
    std::string pointer;  // of the value being checked
    std::string problem;  // the first one found

    bool Fail(std::string reason) {
        problem = std::move(reason);
        return false;
    }

    bool Check(const json& value, const NodeData& s) {
        if (s.kind == Kind::Any || (s.nullable && value.is_null())) return true;
        const std::string expected = std::string(KindName(s.kind)) + (s.nullable ? " or null" : "");
        switch (s.kind) {
            case Kind::Any:
                return true;
            case Kind::Boolean:
                if (!value.is_boolean()) return Fail("must be " + expected + ", not " + Describe(value));
                return true;
            case Kind::Text: {
                if (!value.is_string()) return Fail("must be " + expected + ", not " + Describe(value));
                const std::string& text = value.get_ref<const std::string&>();
                if (s.pathName && !scene_io::IsPathName(text))
                    return Fail(QuoteShown(text) + " is not a name: " + std::string(scene_io::kPathNameRule));
                if (s.allowed.empty()) return true;
                if (std::ranges::find(s.allowed, text) != s.allowed.end()) return true;
                std::vector<std::string_view> names(s.allowed.begin(), s.allowed.end());
                std::string choices;
                for (std::string_view name : names) choices += (choices.empty() ? "" : ", ") + QuoteShown(name);
                // A choice of one needs no "did you mean".
                return Fail("must be one of " + choices + ", not " + QuoteShown(text) +
                            (names.size() > 1 ? Suggest(text, names) : ""));
            }
            case Kind::Number:
            case Kind::Integer: {
                const std::string wanted = std::string(s.kind == Kind::Integer ? "a whole number" : "a number") +
                                           " in " + Range(s.low, s.high) +
                                           (s.nonFiniteText ? " (or \"nan\", \"inf\", \"-inf\")" : "") +
                                           (s.nullable ? " or null" : "");
                if (s.nonFiniteText && value.is_string() && (value == "nan" || value == "inf" || value == "-inf"))
                    return true;
                if (!value.is_number()) return Fail("must be " + wanted + ", not " + Describe(value));
                const double v = value.get<double>();
                // A float that holds a whole number (1e3, 2.0) is one: other tools write counts so.
                const bool whole = value.is_number_integer() || (std::isfinite(v) && v == std::floor(v));
                if (!std::isfinite(v) || v < s.low || v > s.high || (s.kind == Kind::Integer && !whole))
                    return Fail("must be " + wanted + ", got " + value.dump());
                return true;
            }
            case Kind::Array: {
                if (!value.is_array()) return Fail("must be " + expected + ", not " + Describe(value));
                if (value.size() < s.minItems || value.size() > s.maxItems) {
                    const std::string count = s.minItems == s.maxItems ? std::to_string(s.minItems)
                                              : s.maxItems == std::numeric_limits<size_t>::max()
                                                  ? "at least " + std::to_string(s.minItems)
                                                  : std::to_string(s.minItems) + " to " + std::to_string(s.maxItems);
                    return Fail("must have " + count + " elements, has " + std::to_string(value.size()));
                }
                const size_t length = pointer.size();
                for (size_t i = 0; i < value.size(); ++i) {
                    pointer.resize(length);
                    pointer += "/" + std::to_string(i);
                    if (!Check(value[i], *s.element)) return false;
                }
                pointer.resize(length);
                return true;
            }
            case Kind::Object: {
                if (!value.is_object()) return Fail("must be " + expected + ", not " + Describe(value));
                const size_t length = pointer.size();
                if (!s.open) {
                    std::vector<std::string_view> known;
                    for (const Field& f : s.fields) known.push_back(f.name);
                    for (const auto& [key, item] : value.items())
                        if (std::ranges::find(known, key) == known.end()) {
                            pointer += "/" + scene_io::PointerToken(key);
                            return Fail("unknown field" + Suggest(key, known));
                        }
                }
                for (const Field& f : s.fields) {
                    pointer.resize(length);
                    pointer += "/" + scene_io::PointerToken(f.name);
                    const auto it = value.find(f.name);
                    if (it == value.end()) {
                        if (f.required) return Fail("missing");
                        continue;
                    }
                    if (!Check(*it, *f.schema)) return false;
                }
                pointer.resize(length);
                return true;
            }
            case Kind::Either: {
                // The first choice's problem when it is the same kind of value (its detail is the useful one).
                Checker first{pointer, {}}, second{pointer, {}};
                if (first.Check(value, *s.element) || second.Check(value, *s.value)) return true;
                const bool firstKind = SameKind(value, *s.element), secondKind = SameKind(value, *s.value);
                if (firstKind || secondKind) {
                    Checker& closer = firstKind ? first : second;
                    pointer = closer.pointer;
                    return Fail(closer.problem);
                }
                return Fail("must be " + std::string(KindName(s.element->kind)) + " or " +
                            std::string(KindName(s.value->kind)) + ", not " + Describe(value));
            }
            case Kind::Map: {
                if (!value.is_object()) return Fail("must be " + expected + ", not " + Describe(value));
                const size_t length = pointer.size();
                for (const auto& [key, item] : value.items()) {
                    pointer.resize(length);
                    pointer += "/" + scene_io::PointerToken(key);
                    if (std::string why = KeyProblem(s.keys, key); !why.empty()) return Fail(std::move(why));
                    if (!Check(item, *s.value)) return false;
                }
                pointer.resize(length);
                return true;
            }
        }
        return true;
    }
};

}  // namespace

// GCC 12 warns about every member a designated initializer leaves to its default member initializer.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
Node AnyValue() { return Make({}); }
Node Boolean() { return Make({.kind = Kind::Boolean}); }
Node Text() { return Make({.kind = Kind::Text}); }
Node TextOf(std::vector<std::string> allowed) { return Make({.kind = Kind::Text, .allowed = std::move(allowed)}); }
Node Name() { return Make({.kind = Kind::Text, .pathName = true}); }
Node Number(double low, double high) { return Make({.kind = Kind::Number, .low = low, .high = high}); }
Node NumberOrNonFinite(double low, double high) {
    return Make({.kind = Kind::Number, .nonFiniteText = true, .low = low, .high = high});
}
Node Integer(double low, double high) { return Make({.kind = Kind::Integer, .low = low, .high = high}); }

Node Nullable(Node schema) {
    NodeData data = *schema;
    data.nullable = true;
    return Make(std::move(data));
}

Node Either(Node first, Node second) {
    return Make({.kind = Kind::Either, .element = std::move(first), .value = std::move(second)});
}

Node ArrayOf(Node element, size_t minItems, size_t maxItems) {
    return Make({.kind = Kind::Array, .element = std::move(element), .minItems = minItems, .maxItems = maxItems});
}

Node Object(std::vector<Field> fields) { return Make({.kind = Kind::Object, .fields = std::move(fields)}); }
Node OpenObject(std::vector<Field> fields) {
    return Make({.kind = Kind::Object, .fields = std::move(fields), .open = true});
}
Node MapOf(KeyRule keys, Node value) { return Make({.kind = Kind::Map, .keys = keys, .value = std::move(value)}); }
#pragma GCC diagnostic pop

std::vector<std::string_view> FieldNames(const Node& schema) {
    std::vector<std::string_view> names;
    if (schema && schema->kind == Kind::Object)
        for (const Field& f : schema->fields) names.push_back(f.name);
    return names;
}

Status Validate(const nlohmann::json& value, const Node& schema, const std::string& label) {
    Checker checker;
    if (checker.Check(value, *schema)) return {};
    return MakeError(label + ": " + (checker.pointer.empty() ? "/" : ShownText(checker.pointer, false, 200)) + ": " +
                     checker.problem);
}

}  // namespace schema

Result<nlohmann::json> ParseJsonInput(const std::string& text, const std::string& label, const schema::Node& schema) {
    scene_io::JsonDocument doc = scene_io::ParseJsonDocument(text);
    if (doc.failure) return MakeError(label + ": " + scene_io::DescribeParseFailure(text, *doc.failure));
    if (!doc.duplicates.empty())
        return MakeError(label + ": " + ShownText(doc.duplicates.front(), false, 200) + ": duplicate key");
    CB_TRY(schema::Validate(doc.root, schema, label));
    return std::move(doc.root);
}

Result<nlohmann::json> ReadJsonInput(const std::string& path, const InputKind& kind, const schema::Node& schema) {
    Result<std::string> text = ReadInputFile(path, kind);
    if (!text) return std::unexpected(text.error());
    return ParseJsonInput(*text, path, schema);
}

}  // namespace cb
