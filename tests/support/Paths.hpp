// Where the tests find the firmware ELFs and tools the build produced.
#pragma once

#include <string>

namespace avrbench::test {

// The build's folders and the CLI it built, as absolute paths. Defined in
// Paths.cpp, the one test source compiled with them (tests/CMakeLists.txt):
// every other test object is then the same in any clone, so ccache shares
// it between clones (ci/env).
const char* firmware_dir();
const char* source_dir();
const char* cli();

inline std::string firmware(const std::string& name) {
    return std::string(firmware_dir()) + "/" + name + ".elf";
}

inline std::string source_path(const std::string& relative) {
    return std::string(source_dir()) + "/" + relative;
}

}  // namespace avrbench::test
