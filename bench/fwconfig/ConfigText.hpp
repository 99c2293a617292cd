// A firmware's configuration written as C (Marlin's, Prusa's, Repetier's,
// Sprinter's and Teacup's headers, grbl's config.h and defaults.h), read the
// way its compiler would see the settings: `#define NAME VALUE` (continued
// with '\'), `const TYPE NAME = VALUE;` and `TYPE NAME[] = {...};` at the top
// level, inside the branches of #if/#ifdef/#ifndef/#elif/#else its
// preprocessor would take. Conditions are evaluated as the preprocessor does
// for what the files define (defined(), ENABLED(), DISABLED(), arithmetic,
// comparisons, && || !); a name nothing defines is 0. Values are evaluated on
// demand the same way, macros expanded, so `200.0*8/3` or `X_BED_SIZE` give
// numbers. Every value keeps the file and line it came from.
#pragma once

#include <map>
#include <set>
#include <optional>
#include <string>
#include <vector>

namespace avrbench {

struct ConfigEntry {
    std::string name;
    std::string value;  // as written, comments removed, continuation lines joined
    std::string where;  // "Configuration.h:477"
};

class ConfigText {
public:
    // Reads `text` (named `file` in messages) after the files read before it.
    void add(const std::string& text, const std::string& file);

    bool defined(const std::string& name) const { return entries_.count(name) != 0; }
    const ConfigEntry* entry(const std::string& name) const;
    // The value as a number (true/false as 1/0), or empty when it is not one.
    std::optional<double> number(const std::string& name) const;
    // A brace list `{80, 80, 4000, 500}`, each element a number.
    std::optional<std::vector<double>> numbers(const std::string& name) const;
    // "file:line: NAME VALUE", for the comments of a generated board.
    std::string cite(const std::string& name) const;

    // Evaluates an expression as the preprocessor would (0 for unknown names);
    // empty when it cannot be read (a string, a cast it does not know).
    std::optional<double> evaluate(const std::string& expression) const;
    // A macro's value as a number, `depth` macros deep (the evaluator's):
    // each macro evaluated once while the definitions stand (a macro used
    // twice by each of the next, 200 deep, is 200 evaluations, not 2^200),
    // none through itself.
    std::optional<double> macro_value(const std::string& name, int depth) const;

private:
    void forget_values() const { values_.clear(); }
    std::map<std::string, ConfigEntry> entries_;
    mutable std::map<std::string, double> values_;  // macros evaluated since the last #define or #undef
    mutable std::set<std::string> evaluating_;
};

}  // namespace avrbench
