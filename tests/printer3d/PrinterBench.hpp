// Seed 001's five-MCU printer (bench/boards/printer3d-seed001.yaml) with the
// firmware of this repository on every MCU, for the printer3d tests.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "support/Paths.hpp"
#include "run/Bench.hpp"

namespace avrbench::test {

inline std::map<std::string, std::string> printer_firmware(const std::string& interp = "printer3d_interp") {
    return {{"interp", firmware(interp)},
            {"drive_x", firmware("printer3d_drive")},
            {"drive_y", firmware("printer3d_drive")},
            {"drive_z", firmware("printer3d_drive")},
            {"drive_e", firmware("printer3d_drive")},
            {"heater", firmware("printer3d_heater")}};
}

inline std::unique_ptr<Bench> printer_bench(const std::string& interp = "printer3d_interp") {
    return std::make_unique<Bench>(source_path("bench/boards/printer3d-seed001.yaml"), printer_firmware(interp));
}

// Power-on: the drive boards' pull-ups lift the STEP/DIR nets until the
// interpolator makes its pins outputs (low); pin logs made after this see
// only the job. The host listens from power-on, for the "start" banner.
inline std::unique_ptr<Bench> powered_printer(const std::string& interp = "printer3d_interp") {
    auto bench = printer_bench(interp);
    bench->host();
    bench->run_for(0.001);
    return bench;
}

// A little-endian int32_t global of an MCU's firmware (element `index` of an array).
inline std::int32_t ram_i32(Mcu& mcu, const std::string& symbol, int index = 0) {
    const auto b = mcu.read_ram(symbol, static_cast<std::size_t>(4 * (index + 1)));
    const std::size_t o = static_cast<std::size_t>(4 * index);
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(b[o]) | (static_cast<std::uint32_t>(b[o + 1]) << 8) |
                                     (static_cast<std::uint32_t>(b[o + 2]) << 16) |
                                     (static_cast<std::uint32_t>(b[o + 3]) << 24));
}

// The steps a drive board counted (its firmware's `position`, CW positive).
inline std::int32_t drive_position(Bench& bench, const std::string& drive) { return ram_i32(bench.mcu(drive), "position"); }

}  // namespace avrbench::test
