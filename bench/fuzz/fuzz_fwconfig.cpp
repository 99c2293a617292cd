// The firmware-configuration readers of `avrbench board from-config` (C
// headers read as the preprocessor would, grbl's `$$` dump, Klipper's
// printer.cfg) on arbitrary text, in every format: their documented error
// is BadInput (one line for the user).
#include <cstddef>
#include <cstdint>
#include <string>

#include "core/Errors.hpp"
#include "fwconfig/ConfigReaders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<avrbench::ConfigFile> files{{"Configuration.h", std::string(reinterpret_cast<const char*>(data), size)}};
    using avrbench::ConfigFormat;
    for (const ConfigFormat format : {ConfigFormat::Marlin, ConfigFormat::Repetier, ConfigFormat::Teacup, ConfigFormat::Grbl,
                                      ConfigFormat::GrblSettings, ConfigFormat::Klipper}) {
        try {
            (void)avrbench::read_machine_config(format, files);
        } catch (const avrbench::BadInput&) {
        }
    }
    try {
        (void)avrbench::detect_config_format(files);
    } catch (const avrbench::BadInput&) {
    }
    return 0;
}
