// Untrusted text made safe to print in a message: the one escaping rule for
// scene keys and values, parser diagnostics and command-line names.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace cb {

// Longest text shown before it is cut with "..." (in shown characters).
inline constexpr size_t kMaxShownChars = 60;

// `text` safe to print, without quotes: control characters (C0, DEL, C1) escaped as \u00XX, bytes that are not
// UTF-8 as \xHH, '"' and '\\' escaped when `escapeQuotes`, cut to `maxChars` shown characters ending in "..."
// (only the start of a long text is read, so a huge text costs no more than a short one).
std::string ShownText(std::string_view text, bool escapeQuotes = false, size_t maxChars = kMaxShownChars);

// ShownText in double quotes, with quotes and backslashes escaped: how messages show names and values.
std::string QuoteShown(std::string_view text);

}  // namespace cb
