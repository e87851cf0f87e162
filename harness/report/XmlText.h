// Text for XML, HTML and SVG: the report's page and plots, and the JUnit files.
#pragma once

#include <string>
#include <string_view>

namespace cb {

// `text` with &, <, >, " and ' as entities, for element text and attribute values alike, and every control
// character but tab, line feed and carriage return (which XML 1.0 does not allow) as U+FFFD.
std::string EscapeXml(std::string_view text);

}  // namespace cb
