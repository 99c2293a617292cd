// Golden timeline text: parse_timeline_text on arbitrary text.
#include <string>

#include "core/Errors.hpp"
#include "trace/TimelineText.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        (void)avrbench::parse_timeline_text(text, "fuzz.timeline");
    } catch (const avrbench::BadInput&) {
    }
    return 0;
}
