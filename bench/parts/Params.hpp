// Typed part parameters with units and sources. A part declares its
// parameters (ParamSpec); a board file gives text values; resolve_params turns
// them into SI numbers, naming file:line for anything wrong.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/Units.hpp"

namespace avrbench {

enum class ParamType {
    Quantity,  // a number with a unit of `dimension` (or a bare number for Dimensionless)
    Integer,   // a whole number
    Choice,    // one of `choices`
    Text,      // free text (references to other parts)
    Path,      // a file or folder name, relative to the board file that gives it
};

struct ParamSpec {
    std::string name;
    ParamType type = ParamType::Quantity;
    Dimension dimension = Dimension::Dimensionless;
    bool required = false;
    std::string default_value;         // as a user would write it; empty: no default
    std::vector<std::string> choices;  // for Choice
    std::string source;                // where the default comes from (datasheet §, seed, "assumed")
    std::string help;
    // Valid values, inclusive, in SI units (Quantity, Integer). NaN: the
    // dimension's range (dimension_range). Checked with file:line for every
    // value, given, preset or default.
    double min = std::numeric_limits<double>::quiet_NaN();
    double max = std::numeric_limits<double>::quiet_NaN();
};

// What any parameter of a dimension may be, before a part narrows it: the
// physically meaningful range for anything on a bench (no negative
// resistances, times or masses; temperatures above absolute zero; nothing so
// large that the models overflow). Documented in docs/BOARDS.md.
struct ParamRange {
    double min, max;
};
ParamRange dimension_range(Dimension dimension);
ParamRange range_of(const ParamSpec& spec);

// A parameter as written in a board file.
struct RawParam {
    std::string name;
    std::string value;
    std::string location;  // "file:line" for messages
    std::string directory;  // the folder of the board file it is written in (Path parameters start there)
};

class ParamValues {
public:
    double quantity(const std::string& name) const;
    long long integer(const std::string& name) const;
    const std::string& text(const std::string& name) const;  // Choice and Text
    bool has(const std::string& name) const;

    void set_quantity(const std::string& name, double si) { quantities_[name] = si; }
    void set_text(const std::string& name, std::string value) { texts_[name] = std::move(value); }

private:
    std::map<std::string, double> quantities_;
    std::map<std::string, std::string> texts_;
};

// Resolves `given` against `specs`, with `preset` (name -> text) filling in
// before the spec defaults. Throws BadInput "<location>: part '<part>': ..."
// for an unknown parameter, a bad value or unit, or a missing required one
// (then at `part_location`).
ParamValues resolve_params(const std::vector<ParamSpec>& specs, const std::map<std::string, std::string>& preset,
                           const std::vector<RawParam>& given, const std::string& part_name,
                           const std::string& part_location);

}  // namespace avrbench
