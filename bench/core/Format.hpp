// printf into a std::string, for summary and message lines.
#pragma once

#include <string>

namespace avrbench {

std::string format_text(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

}  // namespace avrbench
