// JUnit XML for CI systems (GitLab, Jenkins, GitHub test reporters): one
// <testsuite> with one <testcase> per scenario. The format is the one the
// Jenkins JUnit schema (junit-10.xsd, as used by GitLab and Jenkins)
// accepts; tests validate it against that schema.
#pragma once

#include <string>
#include <vector>

namespace avrbench {

struct JunitCase {
    enum class Outcome { Passed, Failed, Error };
    std::string name;
    std::string classname = "avrbench.scenario";
    double time_s = 0;
    Outcome outcome = Outcome::Passed;
    std::string message;  // one line: the first failure or the error
    std::string text;     // the whole outcome, several lines
};

std::string junit_xml(const std::vector<JunitCase>& cases, const std::string& suite_name);

// Text made safe for XML 1.0 character data and attributes: markup escaped,
// control characters other than tab and newline and bytes that are not
// UTF-8 replaced by '?'; in attributes newlines become &#10;.
std::string xml_escape(const std::string& text, bool attribute);

}  // namespace avrbench
