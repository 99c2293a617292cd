// `--firmware MCU=ELF` (repeatable), as `run` and `fuzz` take it.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/Errors.hpp"

namespace avrbench {

// MCU name -> ELF; BadInput (one line) for an item that is not MCU=ELF.
inline std::map<std::string, std::string> firmware_assignments(const std::vector<std::string>& items) {
    std::map<std::string, std::string> firmware;
    for (const auto& item : items) {
        const auto eq = item.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) {
            throw BadInput("--firmware '" + item + "': expected MCU=ELF");
        }
        firmware[item.substr(0, eq)] = item.substr(eq + 1);
    }
    return firmware;
}

}  // namespace avrbench
