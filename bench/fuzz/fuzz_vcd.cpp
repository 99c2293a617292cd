// The VCD reader on arbitrary text: its documented error is a
// std::runtime_error naming source and line (BadInput is one too).
#include <stdexcept>
#include <string_view>

#include "core/Errors.hpp"
#include "trace/VcdReader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        (void)avrbench::parse_vcd(text, "fuzz.vcd");
    } catch (const std::runtime_error&) {
    }
    return 0;
}
