// What a command reports, apart from how it is shown: a report of titled
// sections holding typed tables, key-value lists, paragraphs, images and
// links, with three renderers: plain text (the terminal), Markdown and JSON;
// harness/report/html/HtmlRender.h renders it as one self-contained HTML page.
// run, conform, accuracy and sweep build their tables here.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace cb::report {

enum class CellType { Text, Integer, Real };

// A column, built by chaining: Column("median ms").Real("%.3f").Unit("ms").Width(10).AlignRight().
struct Column {
    explicit Column(std::string title) : title(std::move(title)) {}
    Column& Real(std::string printfFormat) {
        type = CellType::Real;
        format = std::move(printfFormat);
        return *this;
    }
    Column& Integer() {
        type = CellType::Integer;
        return *this;
    }
    Column& Unit(std::string text) {
        unit = std::move(text);
        return *this;
    }
    Column& Width(int characters) {
        width = characters;
        return *this;
    }
    Column& AlignRight() {
        alignLeft = false;
        return *this;
    }
    Column& Separator(std::string text) {
        separator = std::move(text);
        return *this;
    }
    Column& Prefix(std::string text) {
        prefix = std::move(text);
        return *this;
    }
    Column& NoTextTitle() {
        textTitle = false;
        return *this;
    }

    std::string title;
    CellType type = CellType::Text;
    std::string unit;           // e.g. "ms"; "" = none
    std::string format = "%g";  // printf format of a Real cell
    // Text renderer, Columns layout: minimum width, the text before the cell
    // (a leading indent), a label before a non-empty cell's value, left or
    // right alignment, and whether the header shows the title (notes appended
    // to rows have none).
    int width = 0;
    std::string separator = " ";
    std::string prefix;
    bool alignLeft = true;
    bool textTitle = true;
};

// One value: empty, text, a real or an integer. An empty cell in a column of
// width 0 is left out of the text with its separator, so optional notes at
// the end of a row take no room.
struct Cell {
    enum class Kind { Empty, Text, Real, Integer };
    Cell() = default;
    Cell(std::string value) : kind(Kind::Text), text(std::move(value)) {}
    Cell(const char* value) : kind(Kind::Text), text(value) {}
    Cell(double value) : kind(Kind::Real), real(value) {}
    Cell(int64_t value) : kind(Kind::Integer), integer(value) {}

    Kind kind = Kind::Empty;
    std::string text;
    double real = 0;
    int64_t integer = 0;
};

enum class TextLayout {
    Pipe,     // | a | b |, columns padded: Markdown that reads on a terminal
    Columns,  // space-separated fixed-width columns with an indent
};

struct Table {
    Table() = default;
    explicit Table(std::vector<Column> columns, TextLayout layout = TextLayout::Pipe)
        : columns(std::move(columns)), layout(layout) {}

    std::vector<Column> columns;
    std::vector<std::vector<Cell>> rows;
    TextLayout layout = TextLayout::Pipe;
};

struct KeyValues {
    std::vector<std::pair<std::string, std::string>> items;
};

struct Paragraph {
    std::string text;
};

struct Image {
    std::string path;  // relative to the report's folder
    std::string caption;
    // The encoded file (PNG) when the image is held in memory: the HTML
    // renderer embeds it as a data: URI. The other renderers show `path`.
    std::string data = {};
};

// A plot drawn by the project (harness/report/html/SvgPlot.h), as SVG markup that the
// HTML renderer inlines; text and Markdown show its caption, JSON its kind and caption.
struct Figure {
    std::string kind;  // "box", "history", "pareto"
    std::string svg;
    std::string caption;
};

struct Link {
    std::string target;
    std::string text;
};

using Block = std::variant<Table, KeyValues, Paragraph, Image, Link, Figure>;

struct Section {
    std::string title;
    std::vector<Block> blocks;
};

struct Report {
    explicit Report(std::string title) : title(std::move(title)) {}

    std::string title;
    std::vector<Section> sections;
};

// A cell as the text and Markdown renderers show it.
std::string CellText(const Column& column, const Cell& cell);

// Text: the section title on a line of its own (none when empty), then each block.
std::string RenderText(const Section& section);
std::string RenderText(const Block& block);
// Markdown: "# title", then "## section" per section with its blocks.
std::string RenderMarkdown(const Report& report);
nlohmann::json RenderJson(const Report& report);
// The inverse of RenderJson for its tables, key-value lists, paragraphs,
// images and links (a Real column's format becomes "%g"): the report block of
// a JSON output read back. Throws nlohmann::json::exception on a wrong shape.
Report ReportFromJson(const nlohmann::json& doc);

}  // namespace cb::report
