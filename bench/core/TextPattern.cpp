#include "core/TextPattern.hpp"

#include <re2/re2.h>

#include "core/Errors.hpp"

namespace avrbench {

TextPattern::TextPattern(std::string_view pattern, std::string_view what) : text_(pattern) {
    RE2::Options options;
    options.set_log_errors(false);
    // RE2's default memory budget (8 MiB) bounds a pattern's automaton; a
    // pattern past it fails here, as a bad pattern, not during a run.
    auto re = std::make_shared<const RE2>(re2::StringPiece(text_.data(), text_.size()), options);
    if (!re->ok()) {
        throw BadInput(std::string(what) + ": '" + text_ + "' is not a regular expression: " + re->error());
    }
    re_ = std::move(re);
}

TextPattern::~TextPattern() = default;

bool TextPattern::found_in(std::string_view text) const {
    return RE2::PartialMatch(re2::StringPiece(text.data(), text.size()), *re_);
}

}  // namespace avrbench
