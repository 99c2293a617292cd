// Board files: parse_board_text on arbitrary text.
#include <string>

#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        (void)avrbench::parse_board_text(text, "fuzz.yaml");
    } catch (const avrbench::BadInput&) {
    }
    return 0;
}
