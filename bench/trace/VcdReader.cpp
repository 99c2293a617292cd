#include "trace/VcdReader.hpp"

#include "core/InputFile.hpp"

#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace avrbench {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

// Whitespace-separated tokens with the line each starts on; VCD has no other syntax.
class Tokenizer {
public:
    explicit Tokenizer(std::string_view text) : text_(text) {}

    bool next(std::string_view& token) {
        while (pos_ < text_.size() && is_space(text_[pos_])) {
            if (text_[pos_] == '\n') ++line_;
            ++pos_;
        }
        if (pos_ == text_.size()) return false;
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
        token = text_.substr(start, pos_ - start);
        token_line_ = line_;
        return true;
    }
    // The line of the last token read: after the end of the file, the last line with text.
    std::size_t token_line() const { return token_line_; }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    std::size_t line_ = 1;
    std::size_t token_line_ = 1;
};

class Parser {
public:
    Parser(std::string_view text, const std::string& source) : tokens_(text), source_(source) {}

    VcdDump parse() {
        parse_header();
        parse_values();
        return std::move(dump_);
    }

private:
    [[noreturn]] void fail(std::size_t line, const std::string& what) const {
        throw std::runtime_error(source_ + ":" + std::to_string(line) + ": " + what);
    }
    [[noreturn]] void fail(const std::string& what) const { fail(tokens_.token_line(), what); }

    std::string_view require(const char* what) {
        std::string_view token;
        if (!tokens_.next(token)) fail(std::string("unexpected end of file, expected ") + what);
        return token;
    }
    void require_end(const char* keyword) {
        const std::string_view token = require("$end");
        if (token != "$end") fail("expected $end to close " + std::string(keyword) + ", got '" + std::string(token) + "'");
    }
    // The tokens of a section up to its $end, joined by single spaces.
    std::string section_text(std::string_view keyword) {
        const std::size_t start_line = tokens_.token_line();
        std::string text;
        std::string_view token;
        for (;;) {
            if (!tokens_.next(token))
                fail("unterminated " + std::string(keyword) + " starting at line " +
                                         std::to_string(start_line));
            if (token == "$end") return text;
            if (!token.empty() && token[0] == '$')
                fail("unexpected '" + std::string(token) + "' inside " + std::string(keyword) + " starting at line " +
                     std::to_string(start_line));
            if (!text.empty()) text += ' ';
            text += token;
        }
    }

    template <class Number>
    Number parse_number(std::string_view digits, const char* what) {
        Number value{};
        const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (digits.empty() || error != std::errc() || end != digits.data() + digits.size())
            fail("bad " + std::string(what) + " '" + std::string(digits) + "'");
        return value;
    }

    void parse_timescale(const std::string& text) {
        std::string compact;
        for (const char c : text)
            if (c != ' ') compact += c;
        std::size_t digits = 0;
        while (digits < compact.size() && compact[digits] >= '0' && compact[digits] <= '9') ++digits;
        const std::string number = compact.substr(0, digits);
        const std::string unit = compact.substr(digits);
        static const char* const kUnits[] = {"s", "ms", "us", "ns", "ps", "fs"};
        int unit_index = -1;
        for (int i = 0; i < 6; ++i)
            if (unit == kUnits[i]) unit_index = i;
        if ((number != "1" && number != "10" && number != "100") || unit_index < 0)
            fail("bad $timescale '" + text + "': expected 1, 10 or 100 followed by s, ms, us, ns, ps or fs");
        std::uint64_t fs = std::stoull(number);
        for (int i = unit_index; i < 5; ++i) fs *= 1000;
        dump_.timescale = compact;
        dump_.timescale_fs = fs;
    }

    void parse_var() {
        static const char* const kTypes[] = {"event", "integer", "parameter", "real", "realtime", "reg",
                                              "supply0", "supply1", "time", "tri", "triand", "trior",
                                              "trireg", "tri0", "tri1", "wand", "wire", "wor"};
        VcdVariable var;
        var.type = std::string(require("a $var type"));
        bool known_type = false;
        for (const char* type : kTypes) known_type = known_type || var.type == type;
        if (!known_type) fail("unknown $var type '" + var.type + "'");
        var.width = parse_number<unsigned>(require("a $var size"), "$var size");
        if (var.width == 0) fail("$var size must be at least 1");
        var.id = std::string(require("a $var identifier"));
        // Identifiers may start with '$' ("$" alone is common); only $end means one is missing.
        if (var.id == "$end") fail("$var without identifier and reference");
        var.name = std::string(require("a $var reference"));
        if (var.name == "$end") fail("$var without a reference after identifier '" + var.id + "'");
        // An optional bit range such as "[7:0]", possibly split over tokens.
        for (;;) {
            const std::string_view token = require("$end");
            if (token == "$end") break;
            if (token[0] == '$') fail("unexpected '" + std::string(token) + "' in $var");
            var.name += token;
        }
        var.scope = current_scope();
        const std::size_t index = dump_.variables.size();
        by_id_[var.id].push_back(index);
        dump_.index.emplace(var.full_name(), index);
        dump_.variables.push_back(std::move(var));
    }

    std::string current_scope() const {
        std::string path;
        for (const std::string& scope : scope_stack_) {
            if (!path.empty()) path += '.';
            path += scope;
        }
        return path;
    }

    void parse_header() {
        std::string_view token;
        for (;;) {
            if (!tokens_.next(token)) fail("unexpected end of file before $enddefinitions");
            if (token == "$date" || token == "$comment") {
                section_text(token);
            } else if (token == "$version") {
                dump_.version = section_text(token);
            } else if (token == "$timescale") {
                parse_timescale(section_text(token));
            } else if (token == "$scope") {
                static const char* const kScopeTypes[] = {"module", "task", "function", "begin", "fork"};
                const std::string type(require("a $scope type"));
                bool known_type = false;
                for (const char* t : kScopeTypes) known_type = known_type || type == t;
                if (!known_type) fail("unknown $scope type '" + type + "'");
                const std::string name(require("a $scope name"));
                if (name[0] == '$') fail("missing $scope name before '" + name + "'");
                require_end("$scope");
                scope_stack_.push_back(name);
                dump_.scopes.push_back(current_scope());
            } else if (token == "$upscope") {
                if (scope_stack_.empty()) fail("$upscope without an open $scope");
                require_end("$upscope");
                scope_stack_.pop_back();
            } else if (token == "$var") {
                parse_var();
            } else if (token == "$enddefinitions") {
                require_end("$enddefinitions");
                if (!scope_stack_.empty()) fail("$enddefinitions with $scope '" + current_scope() + "' still open");
                return;
            } else {
                fail("unexpected '" + std::string(token) + "' in the header");
            }
        }
    }

    void apply(std::string_view id, char kind, std::string_view value) {
        const auto found = by_id_.find(std::string(id));
        if (found == by_id_.end()) fail("value change for undeclared identifier '" + std::string(id) + "'");
        for (const std::size_t index : found->second) {
            VcdVariable& var = dump_.variables[index];
            const bool real = var.type == "real" || var.type == "realtime";
            if (kind == 'r' && !real) fail("real value for non-real variable '" + var.full_name() + "'");
            if (kind != 'r' && real) fail("non-real value for real variable '" + var.full_name() + "'");
            if (kind == 's' && var.width != 1)
                fail("scalar value for " + std::to_string(var.width) + "-bit variable '" + var.full_name() + "'");
            if (kind == 'b' && value.size() > var.width)
                fail(std::to_string(value.size()) + "-bit value for " + std::to_string(var.width) +
                     "-bit variable '" + var.full_name() + "'");
            var.changes.push_back(VcdChange{time_, std::string(value)});
        }
    }

    static bool is_logic(char c) {
        return c == '0' || c == '1' || c == 'x' || c == 'X' || c == 'z' || c == 'Z';
    }

    void parse_values() {
        std::string_view token;
        bool in_dump = false;
        std::size_t dump_line = 0;
        std::string dump_keyword;
        while (tokens_.next(token)) {
            const char first = token[0];
            if (first == '#') {
                const auto time = parse_number<std::uint64_t>(token.substr(1), "timestamp");
                if (time < time_)
                    fail("time goes backwards: #" + std::to_string(time) + " after #" + std::to_string(time_));
                time_ = time;
                dump_.end_time = time;
            } else if (token == "$dumpvars" || token == "$dumpall" || token == "$dumpon" || token == "$dumpoff") {
                if (in_dump) fail(std::string(token) + " inside " + dump_keyword + " starting at line " + std::to_string(dump_line));
                in_dump = true;
                dump_line = tokens_.token_line();
                dump_keyword = std::string(token);
            } else if (token == "$end") {
                if (!in_dump) fail("$end without an open section");
                in_dump = false;
            } else if (token == "$comment") {
                section_text(token);
            } else if (is_logic(first)) {
                if (token.size() < 2) fail("scalar value '" + std::string(token) + "' without an identifier");
                apply(token.substr(1), 's', token.substr(0, 1));
            } else if (first == 'b' || first == 'B') {
                const std::string_view bits = token.substr(1);
                if (bits.empty()) fail("vector value 'b' without bits");
                for (const char c : bits)
                    if (!is_logic(c)) fail("bad vector value '" + std::string(token) + "'");
                const std::size_t line = tokens_.token_line();
                const std::string_view id = require("an identifier");
                if (tokens_.token_line() != line) fail(line, "vector value '" + std::string(token) + "' without an identifier");
                apply(id, 'b', bits);
            } else if (first == 'r' || first == 'R') {
                const std::string_view number = token.substr(1);
                double value = 0;
                const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
                if (number.empty() || error != std::errc() || end != number.data() + number.size())
                    fail("bad real value '" + std::string(token) + "'");
                const std::size_t line = tokens_.token_line();
                const std::string_view id = require("an identifier");
                if (tokens_.token_line() != line) fail(line, "real value '" + std::string(token) + "' without an identifier");
                apply(id, 'r', number);
            } else {
                fail("unexpected '" + std::string(token) + "' in the value changes");
            }
        }
        if (in_dump) fail("unterminated " + dump_keyword + " starting at line " + std::to_string(dump_line));
    }

    Tokenizer tokens_;
    const std::string& source_;
    VcdDump dump_;
    std::vector<std::string> scope_stack_;
    std::unordered_map<std::string, std::vector<std::size_t>> by_id_;
    std::uint64_t time_ = 0;
};

}  // namespace

const VcdVariable* VcdDump::find(std::string_view full_name) const {
    const auto it = index.find(full_name);
    return it == index.end() ? nullptr : &variables[it->second];
}

const VcdVariable& VcdDump::at(std::string_view full_name) const {
    const VcdVariable* var = find(full_name);
    if (var == nullptr) throw std::out_of_range("VCD has no variable '" + std::string(full_name) + "'");
    return *var;
}

VcdDump parse_vcd(std::string_view text, const std::string& source) { return Parser(text, source).parse(); }

VcdDump read_vcd(const std::string& path) {
    return parse_vcd(read_input_file(path, "VCD file", kMaxVcdFileBytes), path);
}

}  // namespace avrbench
