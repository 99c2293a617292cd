#include "support/Paths.hpp"

namespace avrbench::test {

const char* firmware_dir() { return AVRBENCH_FIRMWARE_DIR; }
const char* source_dir() { return AVRBENCH_SOURCE_DIR; }
const char* cli() { return AVRBENCH_CLI; }

}  // namespace avrbench::test
