#include "harness/report/ReportTransfer.h"

#include "harness/platform/TransferJson.h"

namespace cb::transfer {

json ToJson(const Summary& s) {
    return {{"count", s.count}, {"median", D(s.median)}, {"q1", D(s.q1)},
            {"q3", D(s.q3)},    {"min", D(s.min)},       {"max", D(s.max)}};
}
Summary SummaryFromJson(const json& j) {
    return {j.at("count").get<size_t>(), FromD(j.at("median")), FromD(j.at("q1")),
            FromD(j.at("q3")),           FromD(j.at("min")),    FromD(j.at("max"))};
}

json ToJson(const std::vector<report::Cell>& cells) {
    json out = json::array();
    for (const report::Cell& c : cells) switch (c.kind) {
            case report::Cell::Kind::Empty:
                out.push_back(nullptr);
                break;
            case report::Cell::Kind::Text:
                out.push_back({{"text", c.text}});
                break;
            case report::Cell::Kind::Real:
                out.push_back({{"real", D(c.real)}});
                break;
            case report::Cell::Kind::Integer:
                out.push_back({{"integer", c.integer}});
                break;
        }
    return out;
}
std::vector<report::Cell> CellsFromJson(const json& j) {
    std::vector<report::Cell> cells;
    for (const json& c : j) {
        if (c.is_null())
            cells.emplace_back();
        else if (c.contains("text"))
            cells.emplace_back(c["text"].get<std::string>());
        else if (c.contains("real"))
            cells.emplace_back(FromD(c["real"]));
        else
            cells.emplace_back(c.at("integer").get<int64_t>());
    }
    return cells;
}

}  // namespace cb::transfer
