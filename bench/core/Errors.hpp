// Error types that map to the CLI's exit codes (docs/CLI.md).
#pragma once

#include <stdexcept>
#include <string>

namespace avrbench {

// Bad usage or input: a missing file, a non-AVR ELF, an unknown MCU, a
// malformed board file. The message is one line naming what and where; the
// CLI prints it and exits with code 2.
class BadInput : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace avrbench
