// Where the tests find the firmware ELFs and tools the build produced.
#pragma once

#include <string>

namespace avrbench::test {

inline std::string firmware(const std::string& name) {
    return std::string(AVRBENCH_FIRMWARE_DIR) + "/" + name + ".elf";
}

inline std::string source_path(const std::string& relative) {
    return std::string(AVRBENCH_SOURCE_DIR) + "/" + relative;
}

}  // namespace avrbench::test
