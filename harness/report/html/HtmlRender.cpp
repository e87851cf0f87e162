#include "harness/report/html/HtmlRender.h"

#include <array>
#include <cstdint>
#include <string_view>

#include "harness/platform/Overloaded.h"
#include "harness/report/html/SvgPlot.h"

namespace cb::html {
namespace {

using report::Block;
using report::CellType;

constexpr std::string_view kStyle = R"(
body { font: 14px/1.45 system-ui, sans-serif; margin: 0 auto; max-width: 1100px; padding: 0 16px 48px; color: #222; }
h1 { font-size: 22px; margin: 20px 0 8px; }
h2 { font-size: 18px; margin: 28px 0 8px; border-bottom: 1px solid #ccc; padding-bottom: 3px; }
nav ol { columns: 2; font-size: 13px; }
table.report { border-collapse: collapse; margin: 8px 0 14px; font-size: 13px; }
table.report th, table.report td { border: 1px solid #ccc; padding: 2px 7px; vertical-align: top; }
table.report th { background: #f2f2f2; text-align: left; }
table.report td.num { text-align: right; font-variant-numeric: tabular-nums; }
dl.kv { display: grid; grid-template-columns: max-content auto; gap: 2px 14px; font-size: 13px; }
dl.kv dt { font-weight: 600; } dl.kv dd { margin: 0; word-break: break-word; }
.st-pass, .st-ok { background: #dff3df; } .st-fail, .st-failed, .st-crashed, .st-timed-out,
.st-out-of-memory { background: #f9d6d5; } .st-skipped, .st-unavailable, .st-unsupported { background: #eee; color: #666; }
figure { margin: 10px 0 18px; } figcaption { font-size: 12px; color: #555; }
figure.frame { display: inline-block; vertical-align: top; max-width: 360px; margin: 6px 14px 12px 0; }
figure.frame img { image-rendering: pixelated; border: 1px solid #ccc; width: 100%; min-width: 240px; }
svg.plot { font: 11px sans-serif; max-width: 100%; height: auto; }
svg.plot .grid { stroke: #e4e4e4; } svg.plot .frame { stroke: #555; } svg.plot .plot-title { font-size: 13px; }
p.verdict-0 { background: #dff3df; padding: 6px 10px; } p.verdict-bad { background: #f9d6d5; padding: 6px 10px; }
)";

constexpr std::array<std::string_view, 10> kStatusWords = {
    "pass", "fail", "skipped", "ok", "failed", "crashed", "timed out", "out of memory", "unavailable", "unsupported"};

std::string StatusClass(const std::string& text) {
    for (std::string_view word : kStatusWords)
        if (text == word) {
            std::string out = "st-" + text;
            for (char& c : out)
                if (c == ' ') c = '-';
            return out;
        }
    return "";
}

std::string TableHtml(const report::Table& table, const std::string& section) {
    std::string out = "<table class=\"report\" data-table=\"" + EscapeXml(section) + "\">\n<thead><tr>";
    for (const report::Column& c : table.columns)
        out += "<th>" + EscapeXml(c.title) + (c.unit.empty() ? "" : " (" + EscapeXml(c.unit) + ")") + "</th>";
    out += "</tr></thead>\n<tbody>\n";
    for (const auto& row : table.rows) {
        out += "<tr>";
        for (size_t c = 0; c < table.columns.size(); ++c) {
            const report::Column& column = table.columns[c];
            const report::Cell cell = c < row.size() ? row[c] : report::Cell();
            std::string cls = column.type == CellType::Text && cell.kind == report::Cell::Kind::Text
                                  ? StatusClass(cell.text)
                                  : std::string(cell.kind == report::Cell::Kind::Text ? "" : "num");
            // The text renderers' label prefix is for a terminal's fixed columns; the HTML has headers.
            report::Column plain = column;
            plain.prefix.clear();
            out += "<td" + (cls.empty() ? "" : " class=\"" + cls + "\"") + ">" +
                   EscapeXml(report::CellText(plain, cell)) + "</td>";
        }
        out += "</tr>\n";
    }
    return out + "</tbody></table>\n";
}

std::string BlockHtml(const Block& block, const std::string& section) {
    return std::visit(
        Overloaded{[&](const report::Table& t) { return TableHtml(t, section); },
                   [](const report::KeyValues& kv) {
                       std::string out = "<dl class=\"kv\">\n";
                       for (const auto& [key, value] : kv.items)
                           out += "<dt>" + EscapeXml(key) + "</dt><dd>" + EscapeXml(value) + "</dd>\n";
                       return out + "</dl>\n";
                   },
                   [](const report::Paragraph& p) { return "<p>" + EscapeXml(p.text) + "</p>\n"; },
                   [](const report::Image& i) {
                       if (i.data.empty())
                           return "<p>" + EscapeXml(i.caption) + ": <code>" + EscapeXml(i.path) + "</code></p>\n";
                       return "<figure class=\"frame\"><img alt=\"" + EscapeXml(i.caption) +
                              "\" src=\"data:image/png;base64," + Base64(i.data) + "\"><figcaption>" +
                              EscapeXml(i.caption) + "</figcaption></figure>\n";
                   },
                   [](const report::Link& l) {
                       if (l.target.starts_with("#"))
                           return "<p><a href=\"" + EscapeXml(l.target) + "\">" + EscapeXml(l.text) + "</a></p>\n";
                       return "<p>" + EscapeXml(l.text) + ": <code>" + EscapeXml(l.target) + "</code></p>\n";
                   },
                   [](const report::Figure& f) {
                       return "<figure class=\"plot\">" + f.svg + "<figcaption>" + EscapeXml(f.caption) +
                              "</figcaption></figure>\n";
                   }},
        block);
}

}  // namespace

std::string RenderHtml(const report::Report& report) {
    std::string out = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
                      EscapeXml(report.title) + "</title>\n<style>" + std::string(kStyle) +
                      "</style>\n</head>\n<body>\n<h1>" + EscapeXml(report.title) + "</h1>\n<nav><ol>\n";
    for (size_t s = 0; s < report.sections.size(); ++s)
        if (!report.sections[s].title.empty())
            out +=
                "<li><a href=\"#s-" + std::to_string(s) + "\">" + EscapeXml(report.sections[s].title) + "</a></li>\n";
    out += "</ol></nav>\n";
    for (size_t s = 0; s < report.sections.size(); ++s) {
        const report::Section& section = report.sections[s];
        out += "<section id=\"s-" + std::to_string(s) + "\">\n";
        if (!section.title.empty()) out += "<h2>" + EscapeXml(section.title) + "</h2>\n";
        for (const Block& block : section.blocks) out += BlockHtml(block, section.title);
        out += "</section>\n";
    }
    return out + "</body>\n</html>\n";
}

std::string Base64(std::string_view bytes) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const uint32_t v =
            uint32_t(uint8_t(bytes[i])) << 16 | uint32_t(uint8_t(bytes[i + 1])) << 8 | uint32_t(uint8_t(bytes[i + 2]));
        out += kAlphabet[v >> 18 & 63];
        out += kAlphabet[v >> 12 & 63];
        out += kAlphabet[v >> 6 & 63];
        out += kAlphabet[v & 63];
    }
    if (const size_t rest = bytes.size() - i; rest > 0) {
        uint32_t v = uint32_t(uint8_t(bytes[i])) << 16;
        if (rest == 2) v |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        out += kAlphabet[v >> 18 & 63];
        out += kAlphabet[v >> 12 & 63];
        out += rest == 2 ? kAlphabet[v >> 6 & 63] : '=';
        out += '=';
    }
    return out;
}

}  // namespace cb::html
