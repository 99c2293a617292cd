#include "fwconfig/ConfigText.hpp"

#include <re2/re2.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "core/Errors.hpp"

namespace avrbench {

namespace {

std::string trim(const std::string& s) {
    const std::size_t b = s.find_first_not_of(" \t\r\n");
    if (b == std::string::npos) return {};
    return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

// Runs of blanks as one, for values quoted in comments.
std::string squeezed(const std::string& s) {
    std::string out;
    for (const char c : trim(s)) {
        if ((c == ' ' || c == '\t') && !out.empty() && out.back() == ' ') continue;
        out += c == '\t' ? ' ' : c;
    }
    return out;
}

// The file's logical lines: continuations joined, comments removed, each
// with the number of its first physical line.
std::vector<std::pair<std::string, std::size_t>> logical_lines(const std::string& text) {
    std::vector<std::pair<std::string, std::size_t>> out;
    std::string current;
    std::size_t first = 1, number = 0;
    bool in_block = false;
    std::istringstream in(text);
    std::string raw;
    while (std::getline(in, raw)) {
        ++number;
        if (current.empty()) first = number;
        std::string kept;
        for (std::size_t i = 0; i < raw.size(); ++i) {
            if (in_block) {
                if (raw.compare(i, 2, "*/") == 0) {
                    in_block = false;
                    ++i;
                    kept += ' ';
                }
                continue;
            }
            if (raw[i] == '"') {  // a string: copied whole (a "//" inside is no comment)
                const std::size_t end = raw.find('"', i + 1);
                const std::size_t stop = end == std::string::npos ? raw.size() : end + 1;
                kept += raw.substr(i, stop - i);
                i = stop - 1;
                continue;
            }
            if (raw.compare(i, 2, "//") == 0) break;
            if (raw.compare(i, 2, "/*") == 0) {
                in_block = true;
                ++i;
                continue;
            }
            kept += raw[i];
        }
        if (!kept.empty() && kept.back() == '\r') kept.pop_back();
        if (!kept.empty() && kept.back() == '\\') {
            kept.pop_back();
            current += kept + " ";
            continue;
        }
        current += kept;
        out.emplace_back(current, first);
        current.clear();
    }
    if (!current.empty()) out.emplace_back(current, first);
    return out;
}

// The preprocessor's expressions, recursive descent over the text.
class Expression {
public:
    Expression(const std::string& text, const ConfigText& config, int depth) : s_(text), config_(config), depth_(depth) {}

    std::optional<double> value() {
        auto v = ternary();
        skip_space();
        if (!v || pos_ != s_.size()) return std::nullopt;
        return v;
    }

private:
    void skip_space() {
        while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])) != 0) ++pos_;
    }
    bool eat(const char* op) {
        skip_space();
        const std::size_t n = std::char_traits<char>::length(op);
        if (s_.compare(pos_, n, op) != 0) return false;
        // "<" is not "<=", "&" is not "&&", "|" not "||", "!" not "!=".
        if (n == 1 && pos_ + 1 < s_.size() && (s_[pos_ + 1] == '=' || s_[pos_ + 1] == s_[pos_]) &&
            std::string("<>!=&|").find(op[0]) != std::string::npos) {
            return false;
        }
        pos_ += n;
        return true;
    }
    std::string identifier() {
        skip_space();
        const std::size_t start = pos_;
        while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) != 0 || s_[pos_] == '_')) ++pos_;
        return s_.substr(start, pos_ - start);
    }

    std::optional<double> ternary() {
        auto c = logical_or();
        if (!c) return std::nullopt;
        if (!eat("?")) return c;
        auto a = ternary();
        if (!a || !eat(":")) return std::nullopt;
        auto b = ternary();
        if (!b) return std::nullopt;
        return *c != 0 ? a : b;
    }
    std::optional<double> logical_or() {
        auto a = logical_and();
        while (a && eat("||")) {
            auto b = logical_and();
            if (!b) return std::nullopt;
            a = (*a != 0 || *b != 0) ? 1.0 : 0.0;
        }
        return a;
    }
    std::optional<double> logical_and() {
        auto a = equality();
        while (a && eat("&&")) {
            auto b = equality();
            if (!b) return std::nullopt;
            a = (*a != 0 && *b != 0) ? 1.0 : 0.0;
        }
        return a;
    }
    std::optional<double> equality() {
        auto a = relational();
        while (a) {
            if (eat("==")) {
                auto b = relational();
                if (!b) return std::nullopt;
                a = *a == *b ? 1.0 : 0.0;
            } else if (eat("!=")) {
                auto b = relational();
                if (!b) return std::nullopt;
                a = *a != *b ? 1.0 : 0.0;
            } else {
                break;
            }
        }
        return a;
    }
    std::optional<double> relational() {
        auto a = additive();
        while (a) {
            int op = eat("<=") ? 1 : eat(">=") ? 2 : eat("<") ? 3 : eat(">") ? 4 : 0;
            if (op == 0) break;
            auto b = additive();
            if (!b) return std::nullopt;
            const bool r = op == 1 ? *a <= *b : op == 2 ? *a >= *b : op == 3 ? *a < *b : *a > *b;
            a = r ? 1.0 : 0.0;
        }
        return a;
    }
    std::optional<double> additive() {
        auto a = multiplicative();
        while (a) {
            if (eat("+")) {
                auto b = multiplicative();
                if (!b) return std::nullopt;
                a = *a + *b;
            } else if (eat("-")) {
                auto b = multiplicative();
                if (!b) return std::nullopt;
                a = *a - *b;
            } else {
                break;
            }
        }
        return a;
    }
    std::optional<double> multiplicative() {
        auto a = unary();
        while (a) {
            if (eat("*")) {
                auto b = unary();
                if (!b) return std::nullopt;
                a = *a * *b;
            } else if (eat("/")) {
                auto b = unary();
                if (!b || *b == 0) return std::nullopt;
                a = *a / *b;
            } else if (eat("%")) {
                auto b = unary();
                if (!b || *b == 0) return std::nullopt;
                a = std::fmod(*a, *b);
            } else {
                break;
            }
        }
        return a;
    }
    // Parentheses and unary operators nest at most this deep: the C standard
    // asks a preprocessor for 63 levels (C11 5.2.4.1); a file with thousands
    // would otherwise run the recursion off the stack.
    static constexpr int kMaxNesting = 256;
    struct Nest {
        int& level;
        explicit Nest(int& l) : level(++l) {}
        ~Nest() { --level; }
    };
    std::optional<double> unary() {
        const Nest nest(nesting_);
        if (nesting_ > kMaxNesting) return std::nullopt;
        if (eat("!")) {
            auto a = unary();
            if (!a) return std::nullopt;
            return *a == 0 ? 1.0 : 0.0;
        }
        if (eat("-")) {
            auto a = unary();
            if (!a) return std::nullopt;
            return -*a;
        }
        if (eat("+")) return unary();
        return primary();
    }
    std::optional<double> primary() {
        skip_space();
        if (pos_ >= s_.size()) return std::nullopt;
        if (eat("(")) {
            auto v = ternary();
            if (!v || !eat(")")) return std::nullopt;
            return v;
        }
        const char c = s_[pos_];
        if (std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '.') {
            char* end = nullptr;
            const double v = std::strtod(s_.c_str() + pos_, &end);
            pos_ = static_cast<std::size_t>(end - s_.c_str());
            while (pos_ < s_.size() && std::strchr("fFlLuU", s_[pos_]) != nullptr) ++pos_;  // 1.0f, 1024L, 10UL
            return v;
        }
        const std::string name = identifier();
        if (name.empty()) return std::nullopt;
        if (name == "true") return 1.0;
        if (name == "false") return 0.0;
        // Arduino's pin levels, which Marlin 2.1's *_ENDSTOP_HIT_STATE use, unless a file defines them.
        if (name == "HIGH" && !config_.defined(name)) return 1.0;
        if (name == "LOW" && !config_.defined(name)) return 0.0;
        if (name == "defined" || name == "ENABLED" || name == "DISABLED" || name == "ANY" || name == "BOTH") {
            const bool parens = eat("(");
            std::vector<std::string> names{identifier()};
            while (parens && eat(",")) names.push_back(identifier());
            if (parens && !eat(")")) return std::nullopt;
            auto on = [&](const std::string& n) {
                if (name == "defined") return config_.defined(n);
                // Marlin's ENABLED(X): X defined empty, or as something true.
                const ConfigEntry* e = config_.entry(n);
                if (e == nullptr) return false;
                if (trim(e->value).empty()) return true;
                if (depth_ > 16) return false;  // defined through itself
                const auto v = config_.macro_value(n, depth_ + 1);
                return v && *v != 0;
            };
            bool any = false, all = true;
            for (const auto& n : names) {
                any = any || on(n);
                all = all && on(n);
            }
            if (name == "DISABLED") return any ? 0.0 : 1.0;
            if (name == "BOTH") return all ? 1.0 : 0.0;
            return any ? 1.0 : 0.0;
        }
        if (depth_ > 16) return std::nullopt;  // a macro defined through itself
        const ConfigEntry* e = config_.entry(name);
        if (e == nullptr) return 0.0;  // the preprocessor's rule for an unknown name
        if (trim(e->value).empty()) return 1.0;
        return config_.macro_value(name, depth_ + 1);
    }

    const std::string& s_;
    const ConfigText& config_;
    int depth_;
    std::size_t pos_ = 0;
    int nesting_ = 0;
};

}  // namespace

void ConfigText::add(const std::string& text, const std::string& file) {
    struct Level {
        bool parent_active;
        bool taken;   // a branch of this #if was active
        bool active;  // this branch is
    };
    std::vector<Level> levels;
    auto active = [&] { return levels.empty() || levels.back().active; };
    // `const bool X = false;`, `float axis_steps_per_unit[] = {...};`, `const int X_MAX_LENGTH = 200;`
    // (RE2, as the project's other patterns: linear time, no recursion).
    static const RE2 declaration(
        R"(\s*(?:static\s+)?(?:const\s+)?(?:bool|int|long|float|double|char|unsigned(?:\s+(?:int|long|char))?|u?int\d+_t)\s+(\w+)\s*(?:\[[^\]]*\])?\s*=\s*(.+?)\s*;\s*)");
    static const RE2 define(R"(\s*#\s*define\s+(\w+)(\(?)(.*))");
    static const RE2 directive(R"(\s*#\s*(\w+)\s*(.*))");
    for (const auto& [line, number] : logical_lines(text)) {
        const std::string where = file + ":" + std::to_string(number);
        std::string word, rest, name, paren, value;
        if (RE2::FullMatch(line, directive, &word, &rest)) {
            rest = trim(rest);
            if (word == "if" || word == "ifdef" || word == "ifndef") {
                bool on = false;
                if (active()) {
                    if (word == "if") {
                        const auto v = evaluate(rest);
                        on = v && *v != 0;
                    } else {
                        on = defined(trim(rest.substr(0, rest.find_first_of(" \t")))) == (word == "ifdef");
                    }
                }
                // A preprocessor must take 63 levels (C11 5.2.4.1); a file of
                // thousands is not a configuration.
                constexpr std::size_t kMaxConditionalNesting = 256;
                if (levels.size() >= kMaxConditionalNesting) {
                    throw BadInput(where + ": #" + word + " nested more than " + std::to_string(kMaxConditionalNesting) + " deep");
                }
                levels.push_back({active(), on, on});
            } else if (word == "elif" && !levels.empty()) {
                Level& l = levels.back();
                bool on = false;
                if (l.parent_active && !l.taken) {
                    const auto v = evaluate(rest);
                    on = v && *v != 0;
                }
                l.active = on;
                l.taken = l.taken || on;
            } else if (word == "else" && !levels.empty()) {
                Level& l = levels.back();
                l.active = l.parent_active && !l.taken;
                l.taken = true;
            } else if (word == "endif" && !levels.empty()) {
                levels.pop_back();
            } else if (word == "define" && active() && RE2::FullMatch(line, define, &name, &paren, &value)) {
                if (!paren.empty()) continue;  // a function-like macro: no setting
                entries_[name] = {name, squeezed(value), where};
                forget_values();
            } else if (word == "undef" && active()) {
                entries_.erase(trim(rest));
                forget_values();
            }
            continue;
        }
        if (active() && RE2::FullMatch(line, declaration, &name, &value)) {
            entries_[name] = {name, squeezed(value), where};
            forget_values();
        }
    }
}

const ConfigEntry* ConfigText::entry(const std::string& name) const {
    const auto it = entries_.find(name);
    return it == entries_.end() ? nullptr : &it->second;
}

std::optional<double> ConfigText::evaluate(const std::string& expression) const {
    return Expression(expression, *this, 0).value();
}

std::optional<double> ConfigText::macro_value(const std::string& name, int depth) const {
    if (const auto known = values_.find(name); known != values_.end()) return known->second;
    const ConfigEntry* e = entry(name);
    if (e == nullptr || evaluating_.count(name) != 0) return std::nullopt;
    evaluating_.insert(name);
    const std::optional<double> v = Expression(e->value, *this, depth).value();
    evaluating_.erase(name);
    // Only values: a failure may be the depth's, not the macro's.
    if (v) values_[name] = *v;
    return v;
}

std::optional<double> ConfigText::number(const std::string& name) const {
    const ConfigEntry* e = entry(name);
    if (e == nullptr) return std::nullopt;
    return evaluate(e->value);
}

std::optional<std::vector<double>> ConfigText::numbers(const std::string& name) const {
    const ConfigEntry* e = entry(name);
    if (e == nullptr) return std::nullopt;
    std::string v = trim(e->value);
    // A list may be a macro naming another: DEFAULT_AXIS_STEPS_PER_UNIT _AXIS_STEP_PER_UNIT.
    for (int hops = 0; hops < 8 && !v.empty() && v.front() != '{'; ++hops) {
        const ConfigEntry* next = entry(v);
        if (next == nullptr) return std::nullopt;
        v = trim(next->value);
    }
    if (v.size() < 2 || v.front() != '{' || v.back() != '}') return std::nullopt;
    std::vector<double> out;
    std::string item;
    int depth = 0;
    for (const char c : v.substr(1, v.size() - 2) + ",") {
        if (c == '(') ++depth;
        if (c == ')') --depth;
        if (c == ',' && depth == 0) {
            if (trim(item).empty()) break;  // a trailing comma
            const auto n = evaluate(item);
            if (!n) return std::nullopt;
            out.push_back(*n);
            item.clear();
            continue;
        }
        item += c;
    }
    return out;
}

std::string ConfigText::cite(const std::string& name) const {
    const ConfigEntry* e = entry(name);
    if (e == nullptr) return name + " (not defined)";
    // A value is quoted whole up to a line's worth; longer, its start and its length.
    constexpr std::size_t kQuoted = 120;
    const std::string value = e->value.size() <= kQuoted
                                  ? e->value
                                  : e->value.substr(0, kQuoted) + "... (" + std::to_string(e->value.size()) + " characters)";
    return e->where + ": " + name + (value.empty() ? "" : " " + value);
}

}  // namespace avrbench
