// Quantities with units as users write them: "2s", "250us", "16MHz",
// "1.9us", "80". One parser so the CLI, board files and scenarios agree.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace avrbench {

// Seconds from "2s", "250ms", "100us", "500ns", "1.5min". A bare number is an
// error (ambiguous). Throws BadInput naming `what` on a bad value or unit.
double parse_seconds(std::string_view text, std::string_view what);

// Hertz from "16MHz", "20 MHz", "32768Hz", "16e6" or "16000000" (a bare
// number is Hz). Throws BadInput naming `what`.
std::uint32_t parse_frequency_hz(std::string_view text, std::string_view what);

}  // namespace avrbench
