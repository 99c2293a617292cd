// Board files: the machine configuration. YAML (yaml-cpp) with MCUs and their
// clocks, parts with parameters, nets joining MCU pins and part pins, serial
// ports for UART hosts, and labels naming pins for later wiring. Structural
// errors are reported as one line "file:line: ..." (BadInput).
//
//   board: arduino-uno-cnc-shield-v3
//   mcus:
//     uno: {type: atmega328p, clock: 16MHz}
//   parts:
//     x_driver: {type: step_dir_driver, preset: a4988, microsteps: 16}
//     x: {type: linear_axis, steps_per_mm: 250, travel: 200mm}
//   nets:
//     x_step: [uno.PD2, x_driver.step]
//     x_motion: [x_driver.steps, x.drive]       # a port net (parts/Part.hpp)
//   serial:
//     host: {mcu: uno, usart: 0, flow: character_counting, rx_buffer: 128}
//   labels:
//     probe: uno.PC5
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "parts/Params.hpp"

namespace avrbench {

struct Endpoint {
    std::string owner;  // MCU or part name
    std::string pin;    // "PD2" or "step"
    std::string location;
    std::string text() const { return owner + "." + pin; }
};

struct McuDecl {
    std::string name;
    std::string type;
    std::uint32_t clock_hz = 0;
    std::string firmware;  // optional default ELF, resolved relative to the board file
    // Optional boot loader (Intel HEX, resolved relative to the board file)
    // and fuse bytes low, high, extended (periph/memory/BootSection.hpp).
    std::string bootloader;
    std::optional<std::array<std::uint8_t, 3>> fuses;
    std::optional<std::uint8_t> lock_bits;  // the lock byte (Boot Lock Bits)
    // `watchdog_resets: expected`: a firmware that resets itself by design;
    // its watchdog resets are no findings (mcu/Mcu.hpp McuOptions).
    bool watchdog_resets_expected = false;
    std::string location;
};

struct PartDecl {
    std::string name;
    std::string type;
    std::vector<RawParam> params;
    std::string location;
};

struct NetDecl {
    std::string name;
    std::vector<Endpoint> endpoints;
    std::string location;
};

struct SerialDecl {
    std::string name;
    std::string mcu;
    int usart = 0;
    std::string flow = "send_and_wait";  // or character_counting
    unsigned rx_buffer_bytes = 128;
    std::string family = "generic";  // stimulus/HostFamily.hpp
    double line_timeout_s = 0;       // no answer for this long (keep-alives restart it); 0: the family's
    std::string location;
};

struct LabelDecl {
    std::string name;
    Endpoint endpoint;
    std::string location;
};

// MCUs on one board at most (docs/BOARDS.md): the lockstep compares every
// core's horizon with every other's, so a run's cost grows with the square of
// the count; seed 001's printer has five.
inline constexpr std::size_t kMaxMcusPerBoard = 16;

struct BoardSpec {
    std::string path;
    std::string name;
    std::string description;
    std::vector<McuDecl> mcus;
    std::vector<PartDecl> parts;
    std::vector<NetDecl> nets;
    std::vector<SerialDecl> serial;
    std::vector<LabelDecl> labels;

    const McuDecl* find_mcu(const std::string& name) const;
    const PartDecl* find_part(const std::string& name) const;
    const SerialDecl* find_serial(const std::string& name) const;
    // A part a host attaches to (a serial_host: parts/HostConnector.hpp).
    bool has_serial_port() const;
    // The MCU the first serial port's nets reach ("" when there is none).
    std::string serial_port_mcu() const;
};

// Reads and checks the file's structure (sections, names, endpoint syntax,
// MCU types and pins, duplicate names). Part types, parameters and part pins
// are checked when the board is built (Board), with the same file:line style.
// `name_or_path` is a file, or the bare name of a standard board
// ("arduino-uno"), looked up in $AVRBENCH_BOARDS_DIR, then beside the
// installed avrbench (<prefix>/share/avrbench/boards), then in the source tree.
BoardSpec load_board_file(const std::string& name_or_path);
std::string find_board_file(const std::string& name_or_path);
std::vector<std::string> standard_board_dirs();
// Where bare boot loader names are looked up: $AVRBENCH_BOOTLOADERS_DIR,
// <prefix>/share/avrbench/bootloaders, then the build tree's.
std::vector<std::string> standard_bootloader_dirs();
BoardSpec parse_board_text(const std::string& text, const std::string& path);

// The standard boards a bare name can select (`avrbench boards`): each name
// once, from the first of standard_board_dirs() that has it, sorted by name.
// A file that does not load is listed with its one-line error.
struct StandardBoard {
    std::string name;
    std::string path;
    std::string description;
    std::string error;  // "" when the file loads
};
std::vector<StandardBoard> list_standard_boards();

}  // namespace avrbench
