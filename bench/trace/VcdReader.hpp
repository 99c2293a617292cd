// A small, strict reader for Value Change Dumps (IEEE 1364-2005 §18): enough to
// check what VcdWriter produced and to read dumps back in tools.
//
// Strict means anything it does not understand is an error, reported as
// std::runtime_error "<source>:<line>: <what>": unknown keywords, unterminated
// sections, values for undeclared identifiers, values wider than their variable,
// values of the wrong kind for their variable, time going backwards.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace avrbench {

struct VcdChange {
    std::uint64_t time;  // in timescale units
    // As written without its type letter: "0", "1", "x", "z" for scalars,
    // "00100000" for vectors (not zero-extended), "25.5" for reals.
    std::string value;
};

struct VcdVariable {
    std::string type;   // "wire", "real", "reg", ...
    unsigned width = 1;
    std::string id;     // identifier code; several variables may share one
    std::string scope;  // enclosing scopes joined with '.', e.g. "mcu" or "top.cpu"
    std::string name;   // reference, with its bit range if declared, e.g. "data[7:0]"
    std::vector<VcdChange> changes;  // in file order, including $dumpvars

    std::string full_name() const { return scope.empty() ? name : scope + "." + name; }
};

struct VcdDump {
    std::string version;    // $version text, whitespace-normalized
    std::string timescale;           // e.g. "100ps"; empty when the file has no $timescale
    std::uint64_t timescale_fs = 0;  // the unit in femtoseconds (1 s = 10^15 fs); 0 when none
    std::vector<std::string> scopes;  // every scope, dotted, in declaration order
    std::vector<VcdVariable> variables;  // in declaration order
    std::uint64_t end_time = 0;  // the last timestamp in the file

    // The variable with that full name ("scope.name"), or nullptr.
    const VcdVariable* find(std::string_view full_name) const;
    // The same, throwing std::out_of_range when missing.
    const VcdVariable& at(std::string_view full_name) const;

    std::map<std::string, std::size_t, std::less<>> index;  // full name -> first variable with it
};

// `source` names the text in error messages (a path, or "<string>").
VcdDump parse_vcd(std::string_view text, const std::string& source = "<string>");
// Throws BadInput naming `path` when it cannot be read (core/InputFile.hpp).
VcdDump read_vcd(const std::string& path);

}  // namespace avrbench
