// JUnit XML, the test report CI systems read (GitLab, Jenkins, GitHub's test reporters): `conform --junit`
// and `perf compare --junit` write one suite of cases with it.
#pragma once

#include <string>
#include <vector>

namespace cb {

struct JUnitCase {
    enum class Result { Pass, Failure, Error, Skipped };
    std::string classname, name;
    Result result = Result::Pass;
    std::string type;     // <failure type=...> or <error type=...>
    std::string message;  // the failure's, error's or skip's message
    std::string text;     // the failure's text, or a passing case's <system-out>; "" for none
};

// <testsuites name=`suites`> holding one <testsuite name=`suite`> of `cases`, with the counts of tests,
// failures, errors and skips on both; text and attributes escaped (a control character XML forbids becomes
// U+FFFD).
std::string JUnitXml(const std::string& suites, const std::string& suite, const std::vector<JUnitCase>& cases);

}  // namespace cb
