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

// Longest command-line argument shown before it is cut with "..." (in bytes of the argument).
inline constexpr size_t kMaxShownArgumentBytes = 40;

// A command-line argument as a usage message shows it (docs/cli.md, "Bad command lines"): printable ASCII as it
// is, every other byte (control characters, every byte of a non-ASCII character) as \xNN, so that a look-alike
// ("\xc3\xa7pu" for a "cpu" typed with a cedilla) shows what differs; cut to kMaxShownArgumentBytes bytes with
// "...".
std::string ShownArgument(std::string_view text);

// `message` with every byte that is not printable ASCII, newline or tab shown as \xNN: the last guard before a
// usage message reaches the terminal, for parts that were not shown with ShownArgument.
std::string ShownMessage(std::string_view message);

}  // namespace cb
