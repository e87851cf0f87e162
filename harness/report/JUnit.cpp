#include "harness/report/JUnit.h"

#include "harness/report/XmlText.h"

namespace cb {

std::string JUnitXml(const std::string& suites, const std::string& suite, const std::vector<JUnitCase>& cases) {
    size_t failures = 0, errors = 0, skipped = 0;
    std::string body;
    for (const JUnitCase& c : cases) {
        body += "    <testcase classname=\"" + EscapeXml(c.classname) + "\" name=\"" + EscapeXml(c.name) + "\"";
        using R = JUnitCase::Result;
        if (c.result == R::Pass && c.text.empty()) {
            body += "/>\n";
            continue;
        }
        body += ">\n";
        switch (c.result) {
            case R::Pass:
                body += "      <system-out>" + EscapeXml(c.text) + "</system-out>\n";
                break;
            case R::Failure:
                ++failures;
                body += "      <failure type=\"" + EscapeXml(c.type) + "\" message=\"" + EscapeXml(c.message) + "\">" +
                        EscapeXml(c.text) + "</failure>\n";
                break;
            case R::Error:
                ++errors;
                body += "      <error type=\"" + EscapeXml(c.type) + "\" message=\"" + EscapeXml(c.message) + "\"/>\n";
                break;
            case R::Skipped:
                ++skipped;
                body += "      <skipped message=\"" + EscapeXml(c.message) + "\"/>\n";
                break;
        }
        body += "    </testcase>\n";
    }
    const std::string counts = "tests=\"" + std::to_string(cases.size()) + "\" failures=\"" + std::to_string(failures) +
                               "\" errors=\"" + std::to_string(errors) + "\" skipped=\"" + std::to_string(skipped) +
                               "\"";
    return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"" + EscapeXml(suites) + "\" " + counts +
           ">\n  <testsuite name=\"" + EscapeXml(suite) + "\" " + counts + ">\n" + body +
           "  </testsuite>\n</testsuites>\n";
}

}  // namespace cb
