#include "harness/report/JUnit.h"

#include <string_view>

namespace cb {
namespace {

// The five markup characters as entities; other control characters but tab and the line ends, which XML 1.0
// does not allow, as U+FFFD.
std::string XmlText(std::string_view text) {
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            case '\'':
                out += "&apos;";
                break;
            default:
                if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r')
                    out += "\xEF\xBF\xBD";
                else
                    out += c;
        }
    }
    return out;
}

}  // namespace

std::string JUnitXml(const std::string& suites, const std::string& suite, const std::vector<JUnitCase>& cases) {
    size_t failures = 0, errors = 0, skipped = 0;
    std::string body;
    for (const JUnitCase& c : cases) {
        body += "    <testcase classname=\"" + XmlText(c.classname) + "\" name=\"" + XmlText(c.name) + "\"";
        using R = JUnitCase::Result;
        if (c.result == R::Pass && c.text.empty()) {
            body += "/>\n";
            continue;
        }
        body += ">\n";
        switch (c.result) {
            case R::Pass:
                body += "      <system-out>" + XmlText(c.text) + "</system-out>\n";
                break;
            case R::Failure:
                ++failures;
                body += "      <failure type=\"" + XmlText(c.type) + "\" message=\"" + XmlText(c.message) + "\">" +
                        XmlText(c.text) + "</failure>\n";
                break;
            case R::Error:
                ++errors;
                body += "      <error type=\"" + XmlText(c.type) + "\" message=\"" + XmlText(c.message) + "\"/>\n";
                break;
            case R::Skipped:
                ++skipped;
                body += "      <skipped message=\"" + XmlText(c.message) + "\"/>\n";
                break;
        }
        body += "    </testcase>\n";
    }
    const std::string counts = "tests=\"" + std::to_string(cases.size()) + "\" failures=\"" + std::to_string(failures) +
                               "\" errors=\"" + std::to_string(errors) + "\" skipped=\"" + std::to_string(skipped) +
                               "\"";
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"" + XmlText(suites) + "\" " + counts +
           ">\n  <testsuite name=\"" + XmlText(suite) + "\" " + counts + ">\n" + body +
           "  </testsuite>\n</testsuites>\n";
}

}  // namespace cb
