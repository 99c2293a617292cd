// SHA-256 of files and strings (OpenSSL), for golden-timeline headers that
// say exactly which firmware, board and stimulus produced a timeline.
#pragma once

#include <string>

namespace avrbench {

// Lower-case hex digest. Throws BadInput naming the path if it cannot be read.
std::string sha256_of_file(const std::string& path);
std::string sha256_of_text(const std::string& text);

}  // namespace avrbench
