// Firmware configurations read into a MachineConfig, one reader per family,
// each following its firmware's documented meaning of the settings:
//
// - Marlin 1.0/1.1/2.x Configuration.h (+ Configuration_adv.h), Prusa-
//   Firmware's variant header (Marlin-derived) and Sprinter's
//   Configuration.h (Marlin's ancestor: the same names as `const bool`);
// - Repetier-Firmware's Configuration.h;
// - Teacup's config.h or printer.*.h with its board.*.h;
// - grbl's config.h + defaults.h, or a `$$` settings dump;
// - Klipper's printer.cfg.
#pragma once

#include <string>
#include <vector>

#include "fwconfig/MachineConfig.hpp"

namespace avrbench {

enum class ConfigFormat { Marlin, Repetier, Teacup, Grbl, GrblSettings, Klipper };

struct ConfigFile {
    std::string path;  // as given, for the comments ("Marlin/Configuration.h")
    std::string text;
};

// The format of the files, from their names and contents; BadInput when
// they match none (say --format).
ConfigFormat detect_config_format(const std::vector<ConfigFile>& files);
// "marlin", "repetier", "teacup", "grbl", "grbl-settings", "klipper".
ConfigFormat config_format_named(const std::string& name);
const char* config_format_name(ConfigFormat format);

MachineConfig read_machine_config(ConfigFormat format, const std::vector<ConfigFile>& files);

}  // namespace avrbench
