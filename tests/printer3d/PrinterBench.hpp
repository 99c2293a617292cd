// Seed 001's five-MCU printer (bench/boards/printer3d-seed001.yaml) with the
// firmware of this repository on every MCU, for the printer3d tests.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "support/Paths.hpp"
#include "verify/Bench.hpp"

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

}  // namespace avrbench::test
