// Shared by the thermal tests: boards written inline, RAM variables of the
// thermal firmwares (firmware/thermal/), exact times of pin edges.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

extern "C" {
#include <sim_avr.h>
}

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "support/Paths.hpp"

namespace avrbench::test {

inline std::unique_ptr<Board> thermal_board(const std::string& yaml, const std::string& firmware,
                                            const std::string& mcu = "mega") {
    return std::make_unique<Board>(parse_board_text(yaml, "thermal-test.yaml"),
                                   std::map<std::string, std::string>{{mcu, test::firmware(firmware)}});
}

inline std::unique_ptr<Board> ramps_board(const std::string& firmware) {
    return Board::from_file(test::source_path("bench/boards/ramps-1.4.yaml"), {{"mega", test::firmware(firmware)}});
}

// Element `index` of a uint16_t array in the firmware's RAM.
inline std::uint16_t read_u16_element(Mcu& mcu, const std::string& symbol, int index) {
    const auto bytes = mcu.read_ram(symbol, 2 * static_cast<std::size_t>(index) + 2);
    return static_cast<std::uint16_t>(bytes[2 * index] | (bytes[2 * index + 1] << 8));
}

inline std::int16_t read_i16(Mcu& mcu, const std::string& symbol) {
    return static_cast<std::int16_t>(mcu.read_ram_u16(symbol));
}

// A single-node hot end: Marlin's MPC block (16.7 J/K, 0.068 W/K), the
// thermistor reading the block itself, a 40 W heater on D10 and the EPCOS
// thermistor on A13, as on RAMPS.
inline const char* kSingleNodeBoard = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: custom, heat_capacity: 16.7J/K, ambient_conductance: 0.068W/K, sensor_time_constant: 0s}
  heater: {type: heater, preset: cartridge_40w_12v}
  t0: {type: thermistor, preset: epcos_b57560g104f}
nets:
  hotend_body: [hotend.body, heater.body, t0.body]
  t0_adc: [mega.PK5, t0.out]
  gate: [mega.PB4, heater.gate]
)";

}  // namespace avrbench::test
