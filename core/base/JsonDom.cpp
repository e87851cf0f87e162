#include "core/base/JsonDom.h"

#include <algorithm>
#include <utility>

#include "core/base/ShownText.h"

namespace cb::scene_io {
namespace {

// How a duplicate key's field is spelled: dotted for scenes ("noise.towers[0].center"), a JSON pointer for the
// harness's input files ("/backends/cpu/stages").
enum class FieldStyle { Dotted, Pointer };

// Builds the document like nlohmann's own DOM parser, recording the field paths of duplicate keys and the
// details of a failure. Each level keeps only its own key or index: a full path is built only for a duplicate, so
// memory stays linear in the depth, which kMaxJsonDepth bounds anyway.
template <typename Json, typename Dom, FieldStyle kStyle>
class DomBuilder final : public nlohmann::json_sax<Json> {
  public:
    using typename nlohmann::json_sax<Json>::number_integer_t;
    using typename nlohmann::json_sax<Json>::number_unsigned_t;
    using typename nlohmann::json_sax<Json>::number_float_t;
    using typename nlohmann::json_sax<Json>::string_t;
    using typename nlohmann::json_sax<Json>::binary_t;

    explicit DomBuilder(Dom& dom) : mDom(dom) {}

    bool null() override { return Put(nullptr); }
    bool boolean(bool value) override { return Put(value); }
    bool number_integer(number_integer_t value) override { return Put(value); }
    bool number_unsigned(number_unsigned_t value) override { return Put(value); }
    bool number_float(number_float_t value, const string_t&) override { return Put(value); }
    bool string(string_t& value) override { return Put(std::move(value)); }
    bool binary(binary_t& value) override { return Put(Json::binary(std::move(value))); }
    bool start_object(std::size_t) override { return Open(Json::object()); }
    bool start_array(std::size_t) override { return Open(Json::array()); }
    bool end_object() override { return Close(); }
    bool end_array() override { return Close(); }

    bool key(string_t& name) override {
        Frame& top = mStack.back();
        if (top.node->contains(name)) mDom.duplicates.push_back(Join(FieldOf(mStack.size()), name));
        top.key = std::move(name);
        return true;
    }

    bool parse_error(std::size_t position, const std::string& lastToken,
                     const nlohmann::detail::exception& error) override {
        mDom.failure = JsonParseFailure{position, lastToken, error.id, error.what()};
        return false;
    }

    // True when the parse stopped because a container opened deeper than kMaxJsonDepth.
    bool TooDeep() const { return mTooDeep; }

  private:
    struct Frame {
        Json* node;
        std::string key;  // last key read, when `node` is an object
    };

    static std::string Join(const std::string& parent, std::string_view key) {
        return kStyle == FieldStyle::Dotted ? JoinField(parent, key) : parent + "/" + PointerToken(key);
    }
    static std::string Index(const std::string& parent, size_t index) {
        return kStyle == FieldStyle::Dotted ? IndexField(parent, index) : parent + "/" + std::to_string(index);
    }

    // Path of the container at level `depth` (1 is the root), built from the levels above it.
    std::string FieldOf(size_t depth) const {
        std::string field;
        for (size_t level = 1; level < depth; ++level) {
            const Frame& parent = mStack[level - 1];
            field = parent.node->is_array() ? Index(field, parent.node->size() - 1) : Join(field, parent.key);
        }
        return field;
    }

    // Stores `value` at the current position; returns its place.
    Json* Place(Json value) {
        if (mStack.empty()) {
            mDom.root = std::move(value);
            return &mDom.root;
        }
        Frame& top = mStack.back();
        if (top.node->is_array()) {
            top.node->push_back(std::move(value));
            return &top.node->back();
        }
        Json& slot = (*top.node)[top.key];
        slot = std::move(value);
        return &slot;
    }

    bool Put(Json value) {
        Place(std::move(value));
        return true;
    }

    bool Open(Json container) {
        if (mStack.size() >= kMaxJsonDepth) {
            mTooDeep = true;
            return false;  // ends the parse; ParseJsonDom finds where
        }
        Json* node = Place(std::move(container));
        mStack.push_back(Frame{node, {}});
        return true;
    }

    bool Close() {
        mStack.pop_back();
        return true;
    }

    Dom& mDom;
    std::vector<Frame> mStack;
    bool mTooDeep = false;
};

// 1-based byte position of the bracket that opens level kMaxJsonDepth + 1 of `text`, which the parser read as
// valid JSON up to there (so strings need only their quotes and escapes followed).
size_t TooDeepPosition(std::string_view text) {
    size_t depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth) return i + 1;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return text.size();
}

// nlohmann's message without its "[json.exception...] parse error at line L, column C: " prefix. The token in
// "last read: '...'" comes from the file: shown as ShownText shows it (escaped, cut short).
std::string ShortReason(const std::string& what) {
    std::string text = what;
    if (size_t p = text.find("] "); p != std::string::npos) text = text.substr(p + 2);
    if (text.starts_with("parse error")) {
        if (size_t p = text.find(": "); p != std::string::npos) text = text.substr(p + 2);
    }
    constexpr std::string_view kLastRead = "last read: '";
    const size_t start = text.find(kLastRead);
    if (start == std::string::npos) return ShownText(text, false, std::string::npos);
    const size_t tokenStart = start + kLastRead.size();
    size_t tokenEnd = text.rfind("'; expected");
    if (tokenEnd == std::string::npos || tokenEnd < tokenStart) tokenEnd = text.rfind('\'');
    if (tokenEnd == std::string::npos || tokenEnd < tokenStart) tokenEnd = text.size();
    return ShownText(std::string_view(text).substr(0, tokenStart), false, std::string::npos) +
           ShownText(std::string_view(text).substr(tokenStart, tokenEnd - tokenStart)) +
           ShownText(std::string_view(text).substr(tokenEnd), false, std::string::npos);
}

// "line L, column C" (1-based) of the character at byte `position` - 1 of `text`.
std::string LineColumn(std::string_view text, size_t position) {
    const size_t offset = std::min(position == 0 ? 0 : position - 1, text.size());
    size_t line = 1, lineStart = 0;
    for (size_t i = 0; i < offset; ++i) {
        if (text[i] == '\n') {
            ++line;
            lineStart = i + 1;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(offset - lineStart + 1);
}

}  // namespace

std::string JoinField(std::string_view parent, std::string_view key) {
    if (parent.empty()) return std::string(key);
    return std::string(parent) + "." + std::string(key);
}

std::string IndexField(std::string_view parent, size_t index) {
    return std::string(parent) + "[" + std::to_string(index) + "]";
}

namespace {

template <typename Json, typename Dom, FieldStyle kStyle>
Dom ParseWith(const std::string& text) {
    Dom dom;
    DomBuilder<Json, Dom, kStyle> builder(dom);
    // Every other refusal goes through parse_error; the fallback only keeps "not JSON" from reading as success.
    if (!Json::sax_parse(text, &builder) && !dom.failure) {
        dom.failure = JsonParseFailure{};
        if (builder.TooDeep()) {
            dom.failure->position = TooDeepPosition(text);
            dom.failure->id = JsonParseFailure::kTooDeepId;
        }
    }
    return dom;
}

}  // namespace

std::string PointerToken(std::string_view key) {
    std::string token;
    for (char c : key) token += c == '~' ? "~0" : c == '/' ? "~1" : std::string(1, c);
    return token;
}

JsonDom ParseJsonDom(const std::string& text) { return ParseWith<Json, JsonDom, FieldStyle::Dotted>(text); }

JsonDocument ParseJsonDocument(const std::string& text) {
    return ParseWith<nlohmann::json, JsonDocument, FieldStyle::Pointer>(text);
}

std::string DescribeParseFailure(std::string_view text, const JsonParseFailure& failure) {
    if (failure.IsNumberOverflow()) {
        // nlohmann's position is the token's last character; point at its first.
        const size_t length = failure.token.size();
        const size_t start = failure.position > length ? failure.position - length + 1 : 1;
        return LineColumn(text, start) + ": the number " + ShownText(failure.token) + " is out of range (not finite)";
    }
    if (failure.IsTooDeep())
        return LineColumn(text, failure.position) + ": nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    return LineColumn(text, failure.position) + ": malformed JSON: " + ShortReason(failure.what);
}

}  // namespace cb::scene_io
