#include "core/base/ShownText.h"

#include <vector>

namespace cb {

std::string ShownText(std::string_view text, bool escapeQuotes, size_t maxChars) {
    auto hex = [](unsigned value) {
        constexpr char kDigits[] = "0123456789abcdef";
        return std::string{kDigits[(value >> 4) & 15], kDigits[value & 15]};
    };
    // One shown character (or escape) per piece; reading stops once the text is known to be too long.
    std::vector<std::string> pieces;
    size_t i = 0;
    while (i < text.size() && pieces.size() <= maxChars) {
        const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[i + k]); };
        const unsigned char c = byte(0);
        // Length of the well-formed UTF-8 sequence starting here; 0 when there is none.
        size_t length = 0;
        if (c < 0x80)
            length = 1;
        else if (c >= 0xC2 && c <= 0xDF)
            length = 2;
        else if ((c & 0xF0) == 0xE0)
            length = 3;
        else if (c >= 0xF0 && c <= 0xF4)
            length = 4;
        if (i + length > text.size()) length = 0;
        for (size_t k = 1; k < length; ++k)
            if ((byte(k) & 0xC0) != 0x80) length = 0;
        if (length == 0) {
            pieces.push_back("\\x" + hex(c));
            length = 1;
        } else if (c < 0x20 || c == 0x7F || (c == 0xC2 && byte(1) < 0xA0)) {
            pieces.push_back("\\u00" + hex(c == 0xC2 ? byte(1) : c));
        } else if (escapeQuotes && (c == '"' || c == '\\')) {
            pieces.push_back(std::string{'\\', char(c)});
        } else {
            pieces.emplace_back(text.substr(i, length));
        }
        i += length;
    }
    if (pieces.size() > maxChars) {
        pieces.resize(maxChars > 3 ? maxChars - 3 : 0);
        pieces.emplace_back("...");
    }
    std::string shown;
    for (const std::string& piece : pieces) shown += piece;
    return shown;
}

namespace {

void AppendByte(std::string& out, unsigned char c, bool keepLineBreaks) {
    constexpr char kDigits[] = "0123456789abcdef";
    if ((c >= 0x20 && c < 0x7F) || (keepLineBreaks && (c == '\n' || c == '\t'))) {
        out.push_back(char(c));
        return;
    }
    out += "\\x";
    out.push_back(kDigits[c >> 4]);
    out.push_back(kDigits[c & 15]);
}

}  // namespace

std::string ShownArgument(std::string_view text) {
    std::string shown;
    for (size_t i = 0; i < text.size() && i < kMaxShownArgumentBytes; ++i)
        AppendByte(shown, static_cast<unsigned char>(text[i]), false);
    if (text.size() > kMaxShownArgumentBytes) shown += "...";
    return shown;
}

std::string ShownMessage(std::string_view message) {
    std::string shown;
    shown.reserve(message.size());
    for (char c : message) AppendByte(shown, static_cast<unsigned char>(c), true);
    return shown;
}

std::string QuoteShown(std::string_view text) {
    // Built with append rather than operator+: GCC 12 raises a false -Wrestrict
    // on "literal" + std::string (GCC bug 105651).
    const std::string shown = ShownText(text, true);
    std::string quoted;
    quoted.reserve(shown.size() + 2);
    quoted.append(1, '"').append(shown).append(1, '"');
    return quoted;
}

}  // namespace cb
