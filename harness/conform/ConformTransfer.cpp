#include "harness/conform/ConformTransfer.h"

#include "harness/platform/TransferJson.h"

namespace cb::transfer {

json ToJson(const ConformRow& r) {
    return {{"stage", r.stage},    {"backend", r.backend},
            {"status", r.status},  {"rule", r.rule},
            {"worst", D(r.worst)}, {"tolerance", D(r.tolerance)},
            {"detail", r.detail},  {"difference_image", r.differenceImage}};
}
ConformRow ConformRowFromJson(const json& j) {
    ConformRow r;
    r.stage = j.at("stage").get<std::string>();
    r.backend = j.at("backend").get<std::string>();
    r.status = j.at("status").get<std::string>();
    r.rule = j.at("rule").get<std::string>();
    r.worst = FromD(j.at("worst"));
    r.tolerance = FromD(j.at("tolerance"));
    r.detail = j.at("detail").get<std::string>();
    r.differenceImage = j.value("difference_image", "");
    return r;
}

}  // namespace cb::transfer
