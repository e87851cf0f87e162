// The schemas of the perf gate's files (internal to harness/report: InputFormats.cpp lists them, PerfSchemas.cpp
// defines them): a kept interleave's interleave.json and `perf compare --json`. They share the provenance and
// report blocks of every output, which InputFormats.cpp defines.
#pragma once

#include <string>
#include <vector>

#include "harness/platform/JsonInput.h"

namespace cb::input::detail {

schema::Node ProvenanceSchema();   // every JSON output's "provenance"
schema::Node ReportBlockSchema();  // every JSON output's "report"
const std::vector<std::string>& SchemaStageNames();  // every stage's name (core/scene/Stage.h), for TextOf
schema::Node InterleaveSchema();   // cloudbench-interleave/1
schema::Node PerfCompareSchema();  // cloudbench-perf-compare/1

}  // namespace cb::input::detail
