// A thermocouple on an AD595 (Marlin's TEMP_SENSOR -1) read by the MCU's ADC:
// the codes firmware/thermal/adc_probe reads, against the datasheet's 10 mV/degC
// computed by hand (ADC = Vin * 1024 / 5 V, truncated, 1023 at most:
// ATmega2560 §26.7; the ADC is fed in mV, rounded).
#include <gtest/gtest.h>

#include "parts/ThermocoupleAmplifier.hpp"
#include "thermal/ThermalTestSupport.hpp"

namespace avrbench {
namespace {

std::unique_ptr<Board> amplifier_at(const std::string& degC) {
    return test::thermal_board(R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: e3d_v6, ambient: )" + degC + ", initial: " + degC + R"(}
  tc: {type: thermocouple_amplifier, preset: ad595}
nets:
  plant_body: [plant.body, tc.body]
  tc_adc: [mega.PK5, tc.out]
)",
                               "thermal_adc_probe_m2560");
}

std::uint16_t code_after_20ms(Board& board) {
    board.run_for_seconds(0.02);
    EXPECT_GT(board.mcu().read_ram_u16("rounds"), 3);
    return test::read_u16_element(board.mcu(), "adc_ch", 0);
}

TEST(ThermocoupleAmplifier, Ad595At25And200DegCReadsTenMillivoltsPerDegree) {
    // 25 degC: 0.25 V -> 0.25 * 1024 / 5 = 51.2 -> 51 (Marlin: 51 * 500 / 1024 = 24.9 degC).
    EXPECT_EQ(code_after_20ms(*amplifier_at("25degC")), 51);
    // 200 degC: 2.00 V -> 409.6 -> 409.
    EXPECT_EQ(code_after_20ms(*amplifier_at("200degC")), 409);
}

TEST(ThermocoupleAmplifier, TheOutputStopsAtTheSupplyAndAnOpenLeadDrivesItThere) {
    // 600 degC would be 6 V: on a 5 V supply the output is at the rail, 1023.
    EXPECT_EQ(code_after_20ms(*amplifier_at("600degC")), 1023);
    auto board = amplifier_at("100degC");
    EXPECT_EQ(code_after_20ms(*board), 204);  // 1.00 V -> 204.8 -> 204
    auto& tc = board->part_as<ThermocoupleAmplifier>("tc");
    EXPECT_DOUBLE_EQ(tc.output_volts(100.0), 1.0);
    tc.inject_fault("open", board->mcu().cycle());
    EXPECT_EQ(code_after_20ms(*board), 1023);
}

}  // namespace
}  // namespace avrbench
