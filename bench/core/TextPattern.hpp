// A regular expression a user gives (a serial port's `expect`, a host's
// error patterns), matched in time linear in the text and without recursion
// (Debian's RE2): a 200 kB line cannot overflow the stack, and a pattern
// such as `(a|a)*b` cannot take exponential time. The syntax is RE2's:
// ECMAScript's and POSIX's usual forms (classes, groups, alternation,
// anchors, repetition, \d \s \w) without backreferences or lookaround.
#pragma once

#include <memory>
#include <string>
#include <string_view>

namespace re2 {
class RE2;
}

namespace avrbench {

class TextPattern {
public:
    // BadInput "<what>: '<pattern>' is not a regular expression: <why>".
    TextPattern(std::string_view pattern, std::string_view what);
    ~TextPattern();
    TextPattern(const TextPattern&) = default;
    TextPattern& operator=(const TextPattern&) = default;

    // Whether the pattern matches anywhere in `text` (unanchored, as
    // Python's re.search and std::regex_search).
    bool found_in(std::string_view text) const;
    const std::string& text() const { return text_; }

private:
    std::string text_;
    std::shared_ptr<const re2::RE2> re_;
};

}  // namespace avrbench
