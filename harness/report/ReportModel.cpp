#include "harness/report/ReportModel.h"

#include <algorithm>
#include <cstdio>

#include "harness/platform/Overloaded.h"

namespace cb::report {
namespace {

using nlohmann::json;

bool IsEmpty(const Cell& cell) { return cell.kind == Cell::Kind::Empty; }

std::string Pad(const std::string& text, size_t width, bool left) {
    if (text.size() >= width) return text;
    const std::string fill(width - text.size(), ' ');
    return left ? text + fill : fill + text;
}

std::string PipeTable(const Table& table) {
    const size_t n = table.columns.size();
    std::vector<size_t> width(n, 3);
    for (size_t c = 0; c < n; ++c) width[c] = std::max(width[c], table.columns[c].title.size());
    for (const auto& row : table.rows)
        for (size_t c = 0; c < row.size() && c < n; ++c)
            width[c] = std::max(width[c], CellText(table.columns[c], row[c]).size());
    auto line = [&](auto&& text) {
        std::string out = "|";
        for (size_t c = 0; c < n; ++c) {
            out += ' ';
            out += Pad(text(c), width[c], true);
            out += " |";
        }
        return out + "\n";
    };
    std::string out = line([&](size_t c) { return table.columns[c].title; }) + "|";
    for (size_t c = 0; c < n; ++c) out += std::string(width[c] + 2, '-') + "|";
    out += "\n";
    for (const auto& row : table.rows)
        out += line([&](size_t c) { return c < row.size() ? CellText(table.columns[c], row[c]) : std::string(); });
    return out;
}

std::string ColumnsTable(const Table& table) {
    auto line = [&](auto&& cellAt) {
        std::string out;
        for (size_t c = 0; c < table.columns.size(); ++c) {
            const Column& column = table.columns[c];
            const Cell cell = cellAt(c);
            if (column.width == 0 && IsEmpty(cell)) continue;
            out += column.separator + Pad(CellText(column, cell), size_t(column.width), column.alignLeft);
        }
        return out + "\n";
    };
    std::string out = line([&](size_t c) -> Cell {
        const Column& column = table.columns[c];
        return column.textTitle ? Cell(column.title) : Cell();
    });
    for (const auto& row : table.rows) out += line([&](size_t c) { return c < row.size() ? row[c] : Cell(); });
    return out;
}

const char* TypeName(CellType type) {
    return type == CellType::Integer ? "integer" : type == CellType::Real ? "real" : "text";
}

json CellJson(const Cell& cell) {
    switch (cell.kind) {
        case Cell::Kind::Text:
            return cell.text;
        case Cell::Kind::Real:
            return cell.real;
        case Cell::Kind::Integer:
            return cell.integer;
        case Cell::Kind::Empty:
            break;
    }
    return nullptr;
}

json BlockJson(const Block& block) {
    return std::visit(Overloaded{[](const Table& t) {
                                     json columns = json::array(), rows = json::array();
                                     for (const Column& c : t.columns) {
                                         json column = {{"title", c.title}, {"type", TypeName(c.type)}};
                                         if (!c.unit.empty()) column["unit"] = c.unit;
                                         columns.push_back(column);
                                     }
                                     for (const auto& row : t.rows) {
                                         json cells = json::array();
                                         for (const Cell& cell : row) cells.push_back(CellJson(cell));
                                         rows.push_back(cells);
                                     }
                                     return json{{"table", {{"columns", columns}, {"rows", rows}}}};
                                 },
                                 [](const KeyValues& kv) {
                                     json items = json::array();
                                     for (const auto& [key, value] : kv.items)
                                         items.push_back({{"key", key}, {"value", value}});
                                     return json{{"key_values", items}};
                                 },
                                 [](const Paragraph& p) {
                                     return json{{"paragraph", p.text}};
                                 },
                                 [](const Image& i) {
                                     return json{{"image", {{"path", i.path}, {"caption", i.caption}}}};
                                 },
                                 [](const Link& l) {
                                     return json{{"link", {{"target", l.target}, {"text", l.text}}}};
                                 },
                                 [](const Figure& f) {
                                     return json{{"figure", {{"kind", f.kind}, {"caption", f.caption}}}};
                                 }},
                      block);
}

std::string BlockMarkdown(const Block& block) {
    return std::visit(Overloaded{[](const Table& t) { return PipeTable(t); },
                                 [](const KeyValues& kv) {
                                     std::string out;
                                     for (const auto& [key, value] : kv.items)
                                         out += "- **" + key + "**: " + value + "\n";
                                     return out;
                                 },
                                 [](const Paragraph& p) { return p.text + "\n"; },
                                 [](const Image& i) { return "![" + i.caption + "](" + i.path + ")\n"; },
                                 [](const Link& l) { return "[" + l.text + "](" + l.target + ")\n"; },
                                 [](const Figure& f) { return "*" + f.caption + "* (" + f.kind + " plot)\n"; }},
                      block);
}

}  // namespace

std::string CellText(const Column& column, const Cell& cell) {
    switch (cell.kind) {
        case Cell::Kind::Text:
            return cell.text.empty() ? cell.text : column.prefix + cell.text;
        case Cell::Kind::Real: {
            char text[64];
            std::snprintf(text, sizeof text, column.format.c_str(), cell.real);
            return column.prefix + text;
        }
        case Cell::Kind::Integer:
            return column.prefix + std::to_string(cell.integer);
        case Cell::Kind::Empty:
            break;
    }
    return "";
}

std::string RenderText(const Block& block) {
    return std::visit(
        Overloaded{[](const Table& t) { return t.layout == TextLayout::Pipe ? PipeTable(t) : ColumnsTable(t); },
                   [](const KeyValues& kv) {
                       std::string out;
                       for (const auto& [key, value] : kv.items) out += key + ": " + value + "\n";
                       return out;
                   },
                   [](const Paragraph& p) { return p.text + "\n"; },
                   [](const Image& i) { return i.caption + ": " + i.path + "\n"; },
                   [](const Link& l) { return l.text + ": " + l.target + "\n"; },
                   [](const Figure& f) { return f.caption + " (" + f.kind + " plot)\n"; }},
        block);
}

std::string RenderText(const Section& section) {
    std::string out = section.title.empty() ? "" : section.title + "\n";
    for (const Block& block : section.blocks) out += RenderText(block);
    return out;
}

std::string RenderMarkdown(const Report& report) {
    std::string out = "# " + report.title + "\n\n";
    for (const Section& section : report.sections) {
        if (!section.title.empty()) out += "## " + section.title + "\n\n";
        for (const Block& block : section.blocks) out += BlockMarkdown(block) + "\n";
    }
    return out;
}

json RenderJson(const Report& report) {
    json sections = json::array();
    for (const Section& section : report.sections) {
        json blocks = json::array();
        for (const Block& block : section.blocks) blocks.push_back(BlockJson(block));
        sections.push_back({{"title", section.title}, {"blocks", blocks}});
    }
    return {{"title", report.title}, {"sections", sections}};
}

Report ReportFromJson(const json& doc) {
    Report report(doc.at("title").get<std::string>());
    for (const json& s : doc.at("sections")) {
        Section section{s.at("title").get<std::string>(), {}};
        for (const json& b : s.at("blocks")) {
            if (b.contains("table")) {
                Table table;
                for (const json& c : b["table"].at("columns")) {
                    Column column(c.at("title").get<std::string>());
                    const std::string type = c.value("type", "text");
                    if (type == "real") column.Real("%g");
                    if (type == "integer") column.Integer();
                    column.Unit(c.value("unit", ""));
                    table.columns.push_back(column);
                }
                for (const json& r : b["table"].at("rows")) {
                    std::vector<Cell> row;
                    for (const json& cell : r) {
                        if (cell.is_string())
                            row.emplace_back(cell.get<std::string>());
                        else if (cell.is_number_integer())
                            row.emplace_back(cell.get<int64_t>());
                        else if (cell.is_number())
                            row.emplace_back(cell.get<double>());
                        else if (cell.is_null())
                            row.emplace_back();
                        else
                            throw json::type_error::create(302, "a table cell is not a string, number or null", &cell);
                    }
                    table.rows.push_back(std::move(row));
                }
                section.blocks.emplace_back(std::move(table));
            } else if (b.contains("key_values")) {
                KeyValues kv;
                for (const json& item : b["key_values"])
                    kv.items.emplace_back(item.at("key").get<std::string>(), item.at("value").get<std::string>());
                section.blocks.emplace_back(std::move(kv));
            } else if (b.contains("paragraph")) {
                section.blocks.emplace_back(Paragraph{b["paragraph"].get<std::string>()});
            } else if (b.contains("image")) {
                section.blocks.emplace_back(
                    Image{b["image"].at("path").get<std::string>(), b["image"].value("caption", ""), ""});
            } else if (b.contains("link")) {
                section.blocks.emplace_back(
                    Link{b["link"].at("target").get<std::string>(), b["link"].value("text", "")});
            }
            // Figures are not read back: their markup is not in the JSON.
        }
        report.sections.push_back(std::move(section));
    }
    return report;
}

}  // namespace cb::report
