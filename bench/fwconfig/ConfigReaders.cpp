#include "fwconfig/ConfigReaders.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "core/Errors.hpp"
#include "fwconfig/ConfigText.hpp"

namespace avrbench {

namespace {

constexpr const char* kAxisUpper[3] = {"X", "Y", "Z"};
constexpr const char* kAxisLower[3] = {"x", "y", "z"};
constexpr const char* kNothingForBaud = ": nothing to set (the host follows the baud rate the firmware programs)";

std::string base_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

ConfigText read_headers(const std::vector<ConfigFile>& files) {
    ConfigText config;
    for (const auto& f : files) config.add(f.text, base_name(f.path));
    return config;
}

std::optional<Sourced<double>> sourced_number(const ConfigText& c, const std::string& name) {
    const auto v = c.number(name);
    if (!v) return std::nullopt;
    return Sourced<double>{*v, c.cite(name)};
}
std::optional<Sourced<bool>> sourced_flag(const ConfigText& c, const std::string& name, bool invert = false) {
    const auto v = c.number(name);
    if (!v) return std::nullopt;
    return Sourced<bool>{(*v != 0) != invert, c.cite(name)};
}
// Marlin's ENABLED(NAME): defined, and empty or true.
bool enabled(const ConfigText& c, const std::string& name) {
    const auto v = c.evaluate("ENABLED(" + name + ")");
    return v && *v != 0;
}

// A board name or number as the firmware's MOTHERBOARD setting gives it, to
// a standard board. RAMPS 1.3/1.4 in every power-output layout: Marlin 1.0's
// and Repetier's numbers 33-35 (and 3 for RAMPS 1.0/1.1), Marlin 1.1/2.x's
// BOARD_RAMPS_13_* / BOARD_RAMPS_14_*; the Einsy RAMBo of a Prusa MK3S.
std::optional<std::string> standard_board_for(const std::string& motherboard) {
    const std::string m = motherboard;
    if (m.find("RAMPS_14") != std::string::npos || m.find("RAMPS_13") != std::string::npos || m == "33" ||
        m == "34" || m == "35" || m == "3") {
        return "ramps-1.4";
    }
    if (m.find("EINSY") != std::string::npos) return "prusa-mk3s";
    return std::nullopt;
}

void note_base(MachineConfig& out, const ConfigText& c, const std::string& setting) {
    const ConfigEntry* e = c.entry(setting);
    if (e == nullptr) {
        out.base_unknown = setting + " not found";
        return;
    }
    if (const auto board = standard_board_for(e->value)) {
        out.base_board = Sourced<std::string>{*board, c.cite(setting)};
    } else {
        out.base_unknown = c.cite(setting) + ": no standard board for it";
    }
}

// A baud rate setting: the host follows whatever UBRR the firmware programs.
void note_baud_rate(MachineConfig& out, const ConfigText& c, const std::string& setting) {
    if (c.defined(setting)) out.not_mapped.push_back(c.cite(setting) + kNothingForBaud);
}

// Marlin's thermistor tables (Marlin's thermistortables.h numbering, which
// Prusa-Firmware and Sprinter share): 1 is the EPCOS 100k B57560G104F, -1
// a thermocouple on an AD595 (Marlin 1.0 Configuration.h: "-1 is thermocouple
// with AD595"; Sprinter's THERMISTORHEATER has no such number).
void thermistor(MachineConfig& out, std::optional<Sourced<std::string>>& slot, const ConfigText& c,
                const std::string& setting) {
    const auto v = c.number(setting);
    if (!v) return;
    if (*v == 1) {
        slot = Sourced<std::string>{"epcos_b57560g104f", c.cite(setting)};
    } else if (*v == -1 && setting.rfind("TEMP_SENSOR_", 0) == 0) {
        slot = Sourced<std::string>{"ad595", c.cite(setting)};
    } else if (*v != 0) {
        out.not_mapped.push_back(c.cite(setting) + ": the bench has no preset for this table (the board's stays)");
    }
}

MachineConfig read_marlin(const std::vector<ConfigFile>& files) {
    const ConfigText c = read_headers(files);
    MachineConfig out;
    const bool sprinter = c.defined("_AXIS_STEP_PER_UNIT") && !c.defined("DEFAULT_AXIS_STEPS_PER_UNIT");
    const bool prusa = c.defined("PRINTER_TYPE") || c.defined("TMC2130_SG_THRS_X");
    out.firmware = sprinter ? "Sprinter" : prusa ? "Prusa-Firmware" : "Marlin";
    note_base(out, c, "MOTHERBOARD");
    // The RepRapDiscount Smart Controller on RAMPS (Marlin 1.1/2.x pins_RAMPS.h, NEWPANEL): the board with its LCD, knob and SD slot.
    if (out.base_board && out.base_board->value == "ramps-1.4" && c.defined("REPRAP_DISCOUNT_SMART_CONTROLLER")) {
        out.base_board = Sourced<std::string>{"ramps-1.4-smart-controller",
                                              out.base_board->source + "; " + c.cite("REPRAP_DISCOUNT_SMART_CONTROLLER")};
    }
    const std::string steps_name = sprinter ? "_AXIS_STEP_PER_UNIT" : "DEFAULT_AXIS_STEPS_PER_UNIT";
    const auto steps = c.numbers(steps_name);
    if (!steps && c.defined(steps_name)) out.not_mapped.push_back(c.cite(steps_name) + ": not a list of numbers");
    const bool all_pullups = c.defined("ENDSTOPPULLUPS");
    for (int k = 0; k < 3; ++k) {
        const std::string A = kAxisUpper[k];
        AxisConfig& a = out.axes[k];
        if (steps && steps->size() > static_cast<std::size_t>(k)) a.steps_per_mm = Sourced<double>{(*steps)[k], c.cite(steps_name)};
        // X_APPLY_DIR(!INVERT_X_DIR) for a + move: DIR high unless inverted.
        a.dir_high_is_plus = sourced_flag(c, "INVERT_" + A + "_DIR", true);
        a.enable_high = sourced_flag(c, A + "_ENABLE_ON");
        a.home_dir = c.number(A + "_HOME_DIR") ? std::optional<Sourced<int>>{{static_cast<int>(*c.number(A + "_HOME_DIR")),
                                                                              c.cite(A + "_HOME_DIR")}}
                                               : std::nullopt;
        a.min_mm = sourced_number(c, A + "_MIN_POS");
        a.max_mm = sourced_number(c, A + "_MAX_POS");
        if (!a.max_mm && c.number(A + "_MAX_LENGTH")) {  // Sprinter: 0 .. X_MAX_LENGTH
            a.max_mm = Sourced<double>{*c.number(A + "_MAX_LENGTH"), c.cite(A + "_MAX_LENGTH")};
            if (!a.min_mm) a.min_mm = Sourced<double>{0.0, c.cite(A + "_MAX_LENGTH") + " (from 0)"};
        }
        // Which ends have switches: USE_XMIN_PLUG (1.1/2.x); before that the homing end.
        for (const char* end : {"MIN", "MAX"}) {
            const std::string plug = "USE_" + A + end + "_PLUG";
            bool present;
            std::string why;
            if (c.defined("USE_XMIN_PLUG") || c.defined("USE_XMAX_PLUG") || c.defined("USE_YMIN_PLUG") ||
                c.defined("USE_ZMIN_PLUG")) {
                present = enabled(c, plug);
                why = present ? c.cite(plug) : plug + " off";
            } else if (a.home_dir) {
                present = (a.home_dir->value < 0) == (std::string(end) == "MIN");
                why = a.home_dir->source;
            } else {
                continue;
            }
            if (!present) continue;
            // READ(X_MIN_PIN) != X_MIN_ENDSTOP_INVERTING: triggered high unless
            // inverting; Marlin 2.1 says the level itself, X_MIN_ENDSTOP_HIT_STATE HIGH/LOW.
            EndstopLogic logic;
            std::string inverting = A + "_" + end + "_ENDSTOP_HIT_STATE";
            if (c.defined(inverting)) {
                logic.triggered_high = c.number(inverting).value_or(1) != 0;
            } else {
                inverting = A + "_" + end + "_ENDSTOP_INVERTING";
                if (!c.defined(inverting)) inverting = A + "_ENDSTOP_INVERT";  // Sprinter
                if (!c.defined(inverting)) inverting = A + "_ENDSTOPS_INVERTING";
                logic.triggered_high = !(c.number(inverting).value_or(0) != 0);
            }
            const std::string pullup = std::string("ENDSTOPPULLUP_") + A + end;
            logic.pull_up = all_pullups || enabled(c, pullup);
            std::string source = why + "; " + c.cite(inverting) + "; " +
                                 (all_pullups ? c.cite("ENDSTOPPULLUPS") : c.defined(pullup) ? c.cite(pullup) : "no pull-up set");
            (std::string(end) == "MIN" ? a.min_switch : a.max_switch) = Sourced<EndstopLogic>{logic, source};
        }
        if (prusa) {
            if (const auto sgt = c.number("TMC2130_SG_THRS_" + A)) {
                a.stall_sgt = Sourced<int>{static_cast<int>(*sgt), c.cite("TMC2130_SG_THRS_" + A)};
            }
            const std::string usteps = k < 2 ? "TMC2130_USTEPS_XY" : "TMC2130_USTEPS_Z";
            if (const auto u = c.number(usteps)) a.microsteps = Sourced<int>{static_cast<int>(*u), c.cite(usteps)};
        } else if (const auto u = c.number(A + "_MICROSTEPS")) {  // Marlin 2.x TMC drivers (Configuration_adv.h)
            a.microsteps = Sourced<int>{static_cast<int>(*u), c.cite(A + "_MICROSTEPS")};
        }
    }
    if (steps && steps->size() > 3) out.e_steps_per_mm = Sourced<double>{(*steps)[3], c.cite(steps_name)};
    if (enabled(c, "Z_SAFE_HOMING")) {
        out.homing_not_judged = c.cite("Z_SAFE_HOMING") + ": G28 ends over the bed (Z_SAFE_HOMING_X/Y_POINT), not at 0";
    }
    // Software endstops: Marlin 1.1/2.x MIN_SOFTWARE_ENDSTOPS; 1.0, Prusa and Sprinter min_software_endstops.
    for (const auto& [flag, slot] : {std::pair{"MIN", &out.soft_min}, std::pair{"MAX", &out.soft_max}}) {
        const std::string upper = std::string(flag) + "_SOFTWARE_ENDSTOPS";
        std::string lower = upper;
        std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
        if (c.defined(upper)) {
            *slot = Sourced<bool>{enabled(c, upper), c.cite(upper)};
        } else if (c.defined(lower)) {
            *slot = sourced_flag(c, lower);
        }
    }
    thermistor(out, out.hotend_thermistor, c, sprinter ? "THERMISTORHEATER" : "TEMP_SENSOR_0");
    thermistor(out, out.bed_thermistor, c, sprinter ? "THERMISTORBED" : "TEMP_SENSOR_BED");
    note_baud_rate(out, c, "BAUDRATE");
    return out;
}

MachineConfig read_repetier(const std::vector<ConfigFile>& files) {
    const ConfigText c = read_headers(files);
    MachineConfig out;
    out.firmware = "Repetier";
    note_base(out, c, "MOTHERBOARD");
    for (int k = 0; k < 3; ++k) {
        const std::string A = kAxisUpper[k];
        AxisConfig& a = out.axes[k];
        a.steps_per_mm = sourced_number(c, A + "AXIS_STEPS_PER_MM");
        a.dir_high_is_plus = sourced_flag(c, "INVERT_" + A + "_DIR", true);
        a.enable_high = sourced_flag(c, A + "_ENABLE_ON");
        if (const auto d = c.number(A + "_HOME_DIR")) a.home_dir = Sourced<int>{static_cast<int>(*d), c.cite(A + "_HOME_DIR")};
        a.min_mm = sourced_number(c, A + "_MIN_POS");
        if (const auto len = c.number(A + "_MAX_LENGTH")) {
            a.max_mm = Sourced<double>{a.min_mm.value_or(Sourced<double>{0, ""}).value + *len,
                                       c.cite(A + "_MAX_LENGTH") + (a.min_mm ? " (from " + A + "_MIN_POS)" : "")};
        }
        for (const char* end : {"MIN", "MAX"}) {
            const std::string hw = std::string(end) + "_HARDWARE_ENDSTOP_" + A;
            if (!(c.number(hw).value_or(0) != 0)) continue;
            const std::string inv = "ENDSTOP_" + A + "_" + end + "_INVERTING";
            const std::string pull = "ENDSTOP_PULLUP_" + A + "_" + end;
            EndstopLogic logic{!(c.number(inv).value_or(0) != 0), c.number(pull).value_or(0) != 0};
            (std::string(end) == "MIN" ? a.min_switch : a.max_switch) =
                Sourced<EndstopLogic>{logic, c.cite(hw) + "; " + c.cite(inv) + "; " + c.cite(pull)};
        }
    }
    // Printer.cpp (homeXAxis...) moves back ENDSTOP_X_BACK_ON_HOME mm after
    // the second approach; run on the board made from the stock
    // configuration, its 0 was that far off the switch (less the steps past
    // it) and Z stood ENDSTOP_Z_BACK_MOVE above its switch until the next
    // move took it down: a G28 whose end the oracle cannot place.
    for (const char* a : {"X", "Y", "Z"}) {
        const std::string back = std::string("ENDSTOP_") + a + "_BACK_ON_HOME";
        if (c.number(back).value_or(0) > 0 && !out.homing_not_judged) {
            out.homing_not_judged = c.cite(back) + ": Repetier moves back after homing and its 0 is not at the switch";
        }
    }
    out.e_steps_per_mm = sourced_number(c, "EXT0_STEPS_PER_MM");
    out.soft_min = sourced_flag(c, "min_software_endstop_x");
    out.soft_max = sourced_flag(c, "max_software_endstop_x");
    note_baud_rate(out, c, "BAUDRATE");
    return out;
}

MachineConfig read_teacup(const std::vector<ConfigFile>& files) {
    const ConfigText c = read_headers(files);
    MachineConfig out;
    out.firmware = "Teacup";
    for (const auto& f : files) {
        if (base_name(f.path).find("ramps") != std::string::npos) {
            out.base_board = Sourced<std::string>{"ramps-1.4", base_name(f.path) + " (a RAMPS board header)"};
        }
    }
    if (!out.base_board) out.base_unknown = "no board.ramps-*.h among the files";
    for (int k = 0; k < 3; ++k) {
        const std::string A = kAxisUpper[k];
        AxisConfig& a = out.axes[k];
        if (const auto per_m = c.number("STEPS_PER_M_" + A)) {
            a.steps_per_mm = Sourced<double>{*per_m / 1000.0, c.cite("STEPS_PER_M_" + A) + " (per metre)"};
        }
        // x_direction(dir): DIR = dir, flipped by X_INVERT_DIR.
        a.dir_high_is_plus = Sourced<bool>{!c.defined(A + "_INVERT_DIR"),
                                           c.defined(A + "_INVERT_DIR") ? c.cite(A + "_INVERT_DIR") : A + "_INVERT_DIR not defined"};
        a.enable_high = Sourced<bool>{!c.defined(A + "_INVERT_ENABLE"),
                                      c.defined(A + "_INVERT_ENABLE") ? c.cite(A + "_INVERT_ENABLE") : A + "_INVERT_ENABLE not defined"};
        a.min_mm = sourced_number(c, A + "_MIN");
        a.max_mm = sourced_number(c, A + "_MAX");
        for (const char* end : {"MIN", "MAX"}) {
            const std::string pin = A + "_" + end + "_PIN";
            if (!c.defined(pin)) continue;
            const std::string inv = A + "_INVERT_" + end;
            EndstopLogic logic{!c.defined(inv), c.defined("USE_INTERNAL_PULLUPS")};
            (std::string(end) == "MIN" ? a.min_switch : a.max_switch) = Sourced<EndstopLogic>{
                logic, c.cite(pin) + "; " + (c.defined(inv) ? c.cite(inv) : inv + " not defined") + "; " +
                           (c.defined("USE_INTERNAL_PULLUPS") ? c.cite("USE_INTERNAL_PULLUPS") : "USE_INTERNAL_PULLUPS not defined")};
        }
        if (a.min_switch) a.home_dir = Sourced<int>{-1, a.min_switch->source};  // G28 homes to the min switches
    }
    // home.c home_axis: a fast approach to the switch, then a slow back-off
    // until it releases, and the position set there - how far past the
    // release the back-off stops depends on its deceleration.
    out.homing_not_judged = "Teacup's home.c zeroes where the switch releases on the slow back-off, a place the "
                            "configuration does not fix to a step";
    if (const auto per_m = c.number("STEPS_PER_M_E")) out.e_steps_per_mm = Sourced<double>{*per_m / 1000.0, c.cite("STEPS_PER_M_E")};
    note_baud_rate(out, c, "BAUD");
    return out;
}

// grbl's settings by number ($100 = X steps/mm), from defaults.h or a dump.
struct GrblSetting {
    double value;
    std::string source;
};

// The board grbl's CPU map (config.h) names: the ATmega328P map is the CNC
// shield's; grbl-Mega's RAMPS map has its own board; its INITIAL map none.
struct GrblBoard {
    std::string firmware;
    std::optional<Sourced<std::string>> board;
    std::string unknown;
};

MachineConfig read_grbl_settings(const std::map<int, GrblSetting>& s, const GrblBoard& board) {
    MachineConfig out;
    out.firmware = board.firmware;
    out.base_board = board.board;
    out.base_unknown = board.unknown;
    auto get = [&](int n) -> const GrblSetting* {
        const auto it = s.find(n);
        return it == s.end() ? nullptr : &it->second;
    };
    const GrblSetting* dir_mask = get(3);
    const GrblSetting* enable_invert = get(4);
    const GrblSetting* limit_invert = get(5);
    const GrblSetting* homing = get(22);
    const GrblSetting* homing_dir = get(23);
    for (int k = 0; k < 3; ++k) {
        AxisConfig& a = out.axes[k];
        if (const auto* v = get(100 + k)) a.steps_per_mm = Sourced<double>{v->value, v->source};
        // grbl drives DIR high for a move towards negative coordinates; $3 flips an axis.
        if (dir_mask) a.dir_high_is_plus = Sourced<bool>{(static_cast<int>(dir_mask->value) >> k & 1) != 0, dir_mask->source};
        if (enable_invert) a.enable_high = Sourced<bool>{enable_invert->value != 0, enable_invert->source};
        if (const auto* t = get(130 + k)) {
            a.min_mm = Sourced<double>{0, t->source};
            a.max_mm = Sourced<double>{std::fabs(t->value), t->source};
        }
        // Limit pins: internal pull-ups, "normal high" (triggered low) unless $5.
        EndstopLogic logic{limit_invert != nullptr && limit_invert->value != 0, true};
        const std::string logic_source = limit_invert ? limit_invert->source : "$5 not given (0: triggered low)";
        if (homing && homing->value != 0) {
            // $23 clear: homes towards + (the max end); set: towards -.
            const bool negative = homing_dir != nullptr && (static_cast<int>(homing_dir->value) >> k & 1) != 0;
            const std::string src = homing->source + "; " + (homing_dir ? homing_dir->source : "$23 not given (0: +)");
            a.home_dir = Sourced<int>{negative ? -1 : 1, src};
            (negative ? a.min_switch : a.max_switch) = Sourced<EndstopLogic>{logic, src + "; " + logic_source};
        } else {
            a.min_switch = Sourced<EndstopLogic>{logic, logic_source + " (homing off: the board's switch end stays)"};
        }
    }
    if (const auto* soft = get(20)) out.soft_min = out.soft_max = Sourced<bool>{soft->value != 0, soft->source};
    return out;
}

MachineConfig read_grbl(const std::vector<ConfigFile>& files) {
    const ConfigText c = read_headers(files);
    std::map<int, GrblSetting> s;
    auto take = [&](int n, const std::string& name) {
        if (const auto v = c.number(name)) s[n] = {*v, c.cite(name)};
    };
    for (int k = 0; k < 3; ++k) {
        take(100 + k, std::string("DEFAULT_") + kAxisUpper[k] + "_STEPS_PER_MM");
        take(130 + k, std::string("DEFAULT_") + kAxisUpper[k] + "_MAX_TRAVEL");
    }
    take(3, "DEFAULT_DIRECTION_INVERT_MASK");
    take(4, "DEFAULT_INVERT_ST_ENABLE");
    take(5, "DEFAULT_INVERT_LIMIT_PINS");
    take(20, "DEFAULT_SOFT_LIMIT_ENABLE");
    take(22, "DEFAULT_HOMING_ENABLE");
    take(23, "DEFAULT_HOMING_DIR_MASK");
    if (s.empty()) throw BadInput("grbl: no DEFAULT_ settings found (give config.h before defaults.h)");
    GrblBoard board{"grbl", Sourced<std::string>{"arduino-uno-cnc-shield-v3", "grbl's ATmega328P pin map"}, ""};
    if (c.defined("CPU_MAP_2560_RAMPS_BOARD")) {
        board = {"grbl-Mega", Sourced<std::string>{"ramps-1.4-grbl-mega", c.cite("CPU_MAP_2560_RAMPS_BOARD")}, ""};
    } else if (c.defined("CPU_MAP_2560_INITIAL")) {
        board = {"grbl-Mega", std::nullopt, c.cite("CPU_MAP_2560_INITIAL") + ": no standard board has this pin map"};
    } else if (c.defined("CPU_MAP_ATMEGA328P")) {
        board.board->source = c.cite("CPU_MAP_ATMEGA328P");
    }
    return read_grbl_settings(s, board);
}

MachineConfig read_grbl_dump(const std::vector<ConfigFile>& files) {
    std::map<int, GrblSetting> s;
    for (const auto& f : files) {
        std::istringstream in(f.text);
        std::string line;
        for (std::size_t number = 1; std::getline(in, line); ++number) {
            if (!line.empty() && line.back() == '\r') line.pop_back();
            if (line.size() < 4 || line[0] != '$') continue;
            const std::size_t eq = line.find('=');
            if (eq == std::string::npos) continue;
            char* end = nullptr;
            const long n = std::strtol(line.c_str() + 1, &end, 10);
            if (end != line.c_str() + eq) continue;
            const double v = std::strtod(line.c_str() + eq + 1, &end);
            if (end == line.c_str() + eq + 1) {
                throw BadInput(base_name(f.path) + ":" + std::to_string(number) + ": '" + line + "' has no number after '='");
            }
            s[static_cast<int>(n)] = {v, base_name(f.path) + ":" + std::to_string(number) + ": " + line.substr(0, line.find(' '))};
        }
    }
    if (s.empty()) throw BadInput("grbl settings: no $N=value lines (the output of $$)");
    // A dump does not say which build: grbl's ATmega328P one unless --base says otherwise.
    return read_grbl_settings(s, {"grbl", Sourced<std::string>{"arduino-uno-cnc-shield-v3", "grbl's ATmega328P pin map (a $$ dump does "
                                                                                            "not name the board)"}, ""});
}

// Klipper's printer.cfg: [section] then "key: value" (or "key = value").
struct IniValue {
    std::string value, where;
};
using Ini = std::map<std::string, std::map<std::string, IniValue>>;

Ini read_ini(const ConfigFile& f) {
    Ini ini;
    std::string section;
    std::istringstream in(f.text);
    std::string line;
    for (std::size_t number = 1; std::getline(in, line); ++number) {
        const std::size_t hash = line.find_first_of("#;");
        if (hash != std::string::npos) line.erase(hash);
        while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back())) != 0) line.pop_back();
        if (line.empty() || std::isspace(static_cast<unsigned char>(line[0])) != 0) continue;  // indented: a continuation
        if (line[0] == '[') {
            section = line.substr(1, line.find(']') - 1);
            continue;
        }
        const std::size_t sep = line.find_first_of(":=");
        if (sep == std::string::npos) continue;
        std::string key = line.substr(0, sep), value = line.substr(sep + 1);
        while (!key.empty() && key.back() == ' ') key.pop_back();
        value.erase(0, value.find_first_not_of(' '));
        ini[section][key] = {value, base_name(f.path) + ":" + std::to_string(number) + ": [" + section + "] " + key + ": " + value};
    }
    return ini;
}

MachineConfig read_klipper(const std::vector<ConfigFile>& files) {
    MachineConfig out;
    out.firmware = "Klipper";
    Ini ini;
    for (const auto& f : files) {
        for (auto& [section, keys] : read_ini(f)) {
            for (auto& [key, value] : keys) ini[section][key] = value;
        }
    }
    auto number = [](const IniValue& v) -> std::optional<double> {
        char* end = nullptr;
        const double d = std::strtod(v.value.c_str(), &end);
        if (end == v.value.c_str()) return std::nullopt;
        return d;
    };
    for (int k = 0; k < 3; ++k) {
        const std::string section = std::string("stepper_") + kAxisLower[k];
        if (ini.count(section) == 0) continue;
        auto& s = ini[section];
        AxisConfig& a = out.axes[k];
        auto find = [&](const char* key) -> const IniValue* { return s.count(key) ? &s[key] : nullptr; };
        if (k == 0 && find("step_pin")) {
            // RAMPS 1.4's X STEP is PF0 (Arduino D54, Klipper's ar54).
            const std::string pin = find("step_pin")->value;
            if (pin == "PF0" || pin == "ar54") out.base_board = Sourced<std::string>{"ramps-1.4", find("step_pin")->where};
            else out.base_unknown = find("step_pin")->where + ": no standard board has X STEP there";
        }
        const IniValue* rotation = find("rotation_distance");
        const IniValue* micro = find("microsteps");
        if (rotation && micro && number(*rotation) && number(*micro) && *number(*rotation) > 0) {
            const IniValue* full = find("full_steps_per_rotation");
            const double full_steps = full && number(*full) ? *number(*full) : 200.0;
            a.steps_per_mm = Sourced<double>{full_steps * *number(*micro) / *number(*rotation),
                                             micro->where + "; " + rotation->where + (full ? "; " + full->where : "; 200 full steps a turn (default)")};
            a.microsteps = Sourced<int>{static_cast<int>(*number(*micro)), micro->where};
        }
        if (find("gear_ratio")) out.not_mapped.push_back(find("gear_ratio")->where + ": gear ratios are not applied");
        // A leading '!' inverts a pin: DIR low is then the + way; ENABLE active low.
        if (const IniValue* dir = find("dir_pin")) a.dir_high_is_plus = Sourced<bool>{dir->value.rfind('!', 0) != 0, dir->where};
        if (const IniValue* en = find("enable_pin")) a.enable_high = Sourced<bool>{en->value.rfind('!', 0) != 0, en->where};
        a.min_mm = Sourced<double>{0, section + ": position_min 0 (default)"};
        if (const IniValue* v = find("position_min"); v && number(*v)) a.min_mm = Sourced<double>{*number(*v), v->where};
        if (const IniValue* v = find("position_max"); v && number(*v)) a.max_mm = Sourced<double>{*number(*v), v->where};
        if (const IniValue* endstop = find("endstop_pin")) {
            // '^' pull-up, '!' inverted (triggered low); "probe:z_virtual_endstop" is no switch.
            std::string pin = endstop->value;
            EndstopLogic logic{true, false};
            while (!pin.empty() && (pin[0] == '^' || pin[0] == '!' || pin[0] == '~')) {
                if (pin[0] == '^') logic.pull_up = true;
                if (pin[0] == '!') logic.triggered_high = false;
                pin.erase(0, 1);
            }
            const IniValue* positive = find("homing_positive_dir");
            const IniValue* at = find("position_endstop");
            bool to_max = positive && (positive->value == "true" || positive->value == "True" || positive->value == "1");
            if (!positive && at && a.max_mm && number(*at) && *number(*at) == a.max_mm->value) to_max = true;
            if (pin.find(':') != std::string::npos) {
                out.not_mapped.push_back(endstop->where + ": a virtual endstop (probe), not a switch");
            } else {
                a.home_dir = Sourced<int>{to_max ? 1 : -1, positive ? positive->where : endstop->where};
                (to_max ? a.max_switch : a.min_switch) = Sourced<EndstopLogic>{logic, endstop->where};
                if (at && number(*at)) {
                    // Klipper calls the switch's position position_endstop.
                    (to_max ? a.max_mm : a.min_mm) = Sourced<double>{*number(*at), at->where};
                }
            }
        }
    }
    if (ini.count("extruder") && ini["extruder"].count("rotation_distance")) {
        out.not_mapped.push_back(ini["extruder"]["rotation_distance"].where + ": the extruder's axis keeps the board's steps");
    }
    if (ini.count("mcu") && ini["mcu"].count("baud")) {
        out.not_mapped.push_back(ini["mcu"]["baud"].where + kNothingForBaud);
    }
    return out;
}

bool contains(const std::string& text, const char* what) { return text.find(what) != std::string::npos; }

}  // namespace

ConfigFormat detect_config_format(const std::vector<ConfigFile>& files) {
    for (const auto& f : files) {
        const std::string name = base_name(f.path);
        if (name.size() > 4 && name.substr(name.size() - 4) == ".cfg") return ConfigFormat::Klipper;
        if (contains(f.text, "[stepper_x]")) return ConfigFormat::Klipper;
        if (contains(f.text, "$100=")) return ConfigFormat::GrblSettings;
    }
    for (const auto& f : files) {
        if (contains(f.text, "XAXIS_STEPS_PER_MM")) return ConfigFormat::Repetier;
        if (contains(f.text, "STEPS_PER_M_X")) return ConfigFormat::Teacup;
        if (contains(f.text, "DEFAULT_X_STEPS_PER_MM") || contains(f.text, "DEFAULTS_GENERIC")) return ConfigFormat::Grbl;
        if (contains(f.text, "DEFAULT_AXIS_STEPS_PER_UNIT") || contains(f.text, "_AXIS_STEP_PER_UNIT")) return ConfigFormat::Marlin;
    }
    throw BadInput("cannot tell the firmware from these files: give --format (marlin, repetier, teacup, grbl, grbl-settings, klipper)");
}

ConfigFormat config_format_named(const std::string& name) {
    for (const ConfigFormat f : {ConfigFormat::Marlin, ConfigFormat::Repetier, ConfigFormat::Teacup, ConfigFormat::Grbl,
                                 ConfigFormat::GrblSettings, ConfigFormat::Klipper}) {
        if (name == config_format_name(f)) return f;
    }
    throw BadInput("--format " + name + ": not one of marlin, repetier, teacup, grbl, grbl-settings, klipper");
}

const char* config_format_name(ConfigFormat format) {
    switch (format) {
        case ConfigFormat::Marlin: return "marlin";
        case ConfigFormat::Repetier: return "repetier";
        case ConfigFormat::Teacup: return "teacup";
        case ConfigFormat::Grbl: return "grbl";
        case ConfigFormat::GrblSettings: return "grbl-settings";
        case ConfigFormat::Klipper: return "klipper";
    }
    return "?";
}

MachineConfig read_machine_config(ConfigFormat format, const std::vector<ConfigFile>& files) {
    switch (format) {
        case ConfigFormat::Marlin: return read_marlin(files);
        case ConfigFormat::Repetier: return read_repetier(files);
        case ConfigFormat::Teacup: return read_teacup(files);
        case ConfigFormat::Grbl: return read_grbl(files);
        case ConfigFormat::GrblSettings: return read_grbl_dump(files);
        case ConfigFormat::Klipper: return read_klipper(files);
    }
    return {};
}

}  // namespace avrbench
