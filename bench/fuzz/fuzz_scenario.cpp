// Scenario files: load_scenario on an arbitrary file (boards and firmware it
// names resolve relative to /tmp, where mostly nothing is).
#include "core/Errors.hpp"
#include "FuzzInput.hpp"
#include "verify/Scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    avrbench::fuzz::InputFile file(data, size, ".yaml");
    try {
        (void)avrbench::load_scenario(file.path(), "/tmp");
    } catch (const avrbench::BadInput&) {
    }
    return 0;
}
