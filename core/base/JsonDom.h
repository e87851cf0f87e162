// JSON text -> document, for the scene loader and (ParseJsonDocument) the
// harness's input files (harness/platform/JsonInput.h). Unlike json::parse it keeps
// where a failure happened (also for number overflow, which json::parse reports
// without a position) and finds duplicate keys instead of silently keeping the
// last one. It exposes nlohmann, which core links privately: only core and the
// harness include it.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cb::scene_io {

// ordered_json keeps the file's key order, so errors come out in reading order.
using Json = nlohmann::ordered_json;

// Dotted field paths as errors spell them: JoinField("ca", "seed") is "ca.seed"
// (just "seed" under an empty parent), IndexField("stages", 2) is "stages[2]".
std::string JoinField(std::string_view parent, std::string_view key);
std::string IndexField(std::string_view parent, size_t index);

// `key` as one token of a JSON pointer (RFC 6901): "~" written "~0", "/" written "~1".
std::string PointerToken(std::string_view key);

// Deepest nesting of arrays and objects accepted; a scene needs 4 levels.
inline constexpr size_t kMaxJsonDepth = 64;

// Why the text is not JSON, as nlohmann's parser reported it.
struct JsonParseFailure {
    size_t position = 0;  // bytes read when it failed (1-based)
    std::string token;    // the last token read
    int id = 0;           // nlohmann's error id
    std::string what;     // nlohmann's message

    // A number beyond the range of a double, such as 1e999.
    bool IsNumberOverflow() const { return id == 406; }

    // Arrays or objects nested deeper than kMaxJsonDepth (an id nlohmann does not use).
    static constexpr int kTooDeepId = -1;
    bool IsTooDeep() const { return id == kTooDeepId; }
};

struct JsonDom {
    Json root;                                // partial when `failure` is set
    std::optional<JsonParseFailure> failure;  // set when the text is not JSON
    std::vector<std::string> duplicates;      // dotted fields of repeated keys, in reading order
};

JsonDom ParseJsonDom(const std::string& text);

// The same for nlohmann::json, with duplicate keys as JSON pointers (RFC 6901: "/backends/cpu/status").
struct JsonDocument {
    nlohmann::json root;                      // partial when `failure` is set
    std::optional<JsonParseFailure> failure;  // set when the text is not JSON
    std::vector<std::string> duplicates;      // JSON pointers of repeated keys, in reading order
};

JsonDocument ParseJsonDocument(const std::string& text);

// "line L, column C: reason" for a failure of ParseJsonDom(text); an overflowing
// number is pointed at by its first character.
std::string DescribeParseFailure(std::string_view text, const JsonParseFailure& failure);

}  // namespace cb::scene_io
