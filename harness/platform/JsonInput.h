// The JSON files cloudbench reads back (docs/cli.md#input-files): read with
// core/base/PathPolicy.h (a regular file of bounded size), parsed with duplicate
// keys and nesting deeper than 64 refused, and checked against a schema before
// any field is used, so that a reader after Validate() may use nlohmann's
// accessors freely.
//
// Every error reads "FILE: FIELD: reason", FIELD a JSON pointer (RFC 6901:
// "/backends/cpu/stages/region/samples_ms/3"): the keys of these files are
// data (a scene may be named "thesis.v2"), so a dotted path would be
// ambiguous; the scene files, whose keys are fixed, keep their dotted fields.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"
#include "core/base/PathPolicy.h"

namespace cb {

namespace schema {

// What a map's keys must be, checked with a "did you mean" on a miss.
enum class KeyRule {
    Any,       // any text
    Backend,   // a backend the registry knows: cpu, gl, vk
    Stage,     // a stage of core/scene/Stage.h
    PathName,  // a scene or camera name (core/scene/SceneValidator.h kPathNameRule)
};

struct NodeData;
// A schema: what one JSON value must be. Built from the functions below, shared by value.
using Node = std::shared_ptr<const NodeData>;

struct Field {
    std::string name;
    Node schema;
    bool required = false;
};

Node AnyValue();  // anything (a provenance's free-form parts)
Node Boolean();
Node Text();
Node TextOf(std::vector<std::string> allowed);  // one of these strings
Node Name();  // a file, scene or camera name (core/scene/SceneValidator.h kPathNameRule): never a path
// A finite number in [low, high].
Node Number(double low = -std::numeric_limits<double>::max(), double high = std::numeric_limits<double>::max());
// A number in [low, high], or one of the strings "nan", "inf", "-inf" that stand for the values JSON cannot
// hold (harness/platform/TransferJson.h writes error statistics so).
Node NumberOrNonFinite(double low = -std::numeric_limits<double>::max(),
                       double high = std::numeric_limits<double>::max());
// A whole number in [low, high] (written as an integer or as a float with no fraction).
Node Integer(double low, double high);
Node Nullable(Node schema);            // null or `schema`
Node Either(Node first, Node second);  // a value that is `first` or `second` (tried in that order)
Node ArrayOf(Node element, size_t minItems = 0, size_t maxItems = std::numeric_limits<size_t>::max());
// An object with these fields; any other key is refused ("unknown field", with a "did you mean").
Node Object(std::vector<Field> fields);
// An object with these fields and any other keys, not checked (for blocks other tools may extend).
Node OpenObject(std::vector<Field> fields);
// An object whose keys follow `keys`, each value `value`.
Node MapOf(KeyRule keys, Node value);

// The first way `value` breaks `schema`, as "LABEL: POINTER: reason" (the root's pointer shown as "/").
Status Validate(const nlohmann::json& value, const Node& schema, const std::string& label);

// The field names of an object schema (Object or OpenObject), in their order; none for any other schema.
std::vector<std::string_view> FieldNames(const Node& schema);

}  // namespace schema

// A JSON document read from `path`: the text (ReadInputFile with `kind`), JSON with no duplicate key, then
// `schema`. Errors: "PATH: not a regular file (a FIFO)", "PATH: line L, column C: malformed JSON: ...",
// "PATH: /scene/name: duplicate key", "PATH: /backends/cpuu: unknown backend "cpuu" (did you mean "cpu"?)".
Result<nlohmann::json> ReadJsonInput(const std::string& path, const InputKind& kind, const schema::Node& schema);

// The same for a document already in memory (`label` names it in errors, e.g. "history.jsonl:12").
Result<nlohmann::json> ParseJsonInput(const std::string& text, const std::string& label, const schema::Node& schema);

}  // namespace cb
