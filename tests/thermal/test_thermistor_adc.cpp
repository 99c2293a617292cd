// The thermistor, its divider and the MCU's ADC: the codes a firmware reads,
// against divider values computed by hand from datasheet resistances.
// firmware/thermal/adc_probe converts its channels in a loop. periph/adc/Adc feeds
// each channel's voltage (in mV, rounded) when a conversion starts; the
// conversion is the core's (fixes/AdcConversion): ADC = Vin * 1024 / Vref,
// truncated, clamped to 1023 (ATmega2560 §26.7).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "periph/adc/Adc.hpp"
#include "parts/Heater.hpp"
#include "parts/ThermalPlant.hpp"
#include "parts/Thermistor.hpp"
#include "thermal/ThermalTestSupport.hpp"

namespace avrbench {
namespace {

// A plant held at `degC` (ambient = initial = degC, no heater: it stays there).
std::string held_at(const std::string& degC, const std::string& thermistor, const std::string& extra = "") {
    return R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: e3d_v6, ambient: )" +
           degC + ", initial: " + degC + R"(}
  t0: {type: thermistor, preset: )" +
           thermistor + R"()" + extra + R"(}
nets:
  plant_body: [plant.body, t0.body]
  t0_adc: [mega.PK5, t0.out]
)";
}

struct ProbeRun {
    std::unique_ptr<Board> board;
    explicit ProbeRun(const std::string& yaml, const std::string& fw = "thermal_adc_probe_m2560",
                      const std::string& mcu = "mega")
        : board(test::thermal_board(yaml, fw, mcu)) {
        board->run_for_seconds(0.02);
        EXPECT_GT(board->mcu().read_ram_u16("rounds"), 3);
    }
    std::uint16_t adc_ch(int index) { return test::read_u16_element(board->mcu(), "adc_ch", index); }
};

TEST(ThermistorAdc, EpcosAt25DegCReadsTheHandComputedCode) {
    // EPCOS B57560G104F: 100 kohm at 25 degC. RAMPS divider: V = 5 * 100000 / 104700
    // = 4.77555 V (fed as 4776 mV); ADC = V * 1024 / 5 = 978.03 -> 978.
    ProbeRun run(held_at("25degC", "epcos_b57560g104f"));
    EXPECT_NEAR(run.adc_ch(0), 978, 1);
    EXPECT_EQ(run.adc_ch(0), 978);
    // ADLAR: the 10-bit code left-adjusted, ADCH alone = code >> 2 = 244.
    EXPECT_EQ(run.board->mcu().read_ram_u8("adc_high8"), 978 >> 2);
}

TEST(ThermistorAdc, EpcosAt150DegCReadsTheHandComputedCode) {
    // Datasheet point 1641.9 ohm at 150 degC: V = 5 * 1641.9 / 6341.9 = 1.29449 V;
    // ADC = 1.29449 * 1024 / 5 = 265.11 -> 265.
    ProbeRun run(held_at("150degC", "epcos_b57560g104f"));
    EXPECT_NEAR(run.adc_ch(0), 265, 1);
}

TEST(ThermistorAdc, Ntc3950At25And200DegCReadTheHandComputedCodes) {
    // beta 3950: R(200 degC) = 100k * exp(3950 * (1/473.15 - 1/298.15)) = 744.61 ohm;
    // V = 5 * 744.61 / 5444.61 = 0.68381 V; ADC = 140.04 -> 140.
    ProbeRun hot(held_at("200degC", "ntc_100k_3950"));
    EXPECT_NEAR(hot.adc_ch(0), 140, 1);
    // At 25 degC the 3950 part is 100 kohm too: 978.
    ProbeRun cold(held_at("25degC", "ntc_100k_3950"));
    EXPECT_NEAR(cold.adc_ch(0), 978, 1);
}

TEST(ThermistorAdc, EpcosAt200DegCMatchesTheSteinhartHartFit) {
    // Between datasheet points the curve is the Steinhart-Hart fit through
    // them; by hand (A = 7.22136e-4, B = 2.16767e-4, C = 8.92936e-8, Cardano):
    // R(200 degC) = 552.78 ohm, V = 5 * 552.78 / 5252.78 = 0.52618 V,
    // ADC = 107.76 -> 108.
    ProbeRun run(held_at("200degC", "epcos_b57560g104f"));
    EXPECT_NEAR(run.adc_ch(0), 108, 1);
    auto& t0 = run.board->part_as<Thermistor>("t0");
    EXPECT_NEAR(t0.curve().resistance_ohm(200.0), 552.78, 0.01);
    EXPECT_NEAR(t0.curve().a, 7.22136e-4, 1e-9);
    EXPECT_NEAR(t0.curve().b, 2.16767e-4, 1e-9);
    EXPECT_NEAR(t0.curve().c, 8.92936e-8, 1e-12);
}

TEST(ThermistorAdc, SteinhartHartFitPassesThroughTheDatasheetPoints) {
    const NtcCurve c = NtcCurve::fit({{{25.0, 100000.0}, {150.0, 1641.9}, {250.0, 226.15}}});
    EXPECT_NEAR(c.resistance_ohm(25.0), 100000.0, 1e-3);
    EXPECT_NEAR(c.resistance_ohm(150.0), 1641.9, 1e-6);
    EXPECT_NEAR(c.resistance_ohm(250.0), 226.15, 1e-6);
    EXPECT_NEAR(c.temperature_degC(1641.9), 150.0, 1e-9);
    // The beta model is Steinhart-Hart with C = 0.
    const NtcCurve b = NtcCurve::from_beta(100000.0, 25.0, 3950.0);
    EXPECT_NEAR(b.c, 0.0, 1e-15);
    EXPECT_NEAR(b.resistance_ohm(200.0), 744.61, 0.01);
}

TEST(ThermistorAdc, ChannelsAboveSevenAndBelowEightAreIndependent) {
    // simavr 1.6 keeps only ADC0..7; the bench serves ADC8..15 (Port K) too.
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: e3d_v6, ambient: 25degC}
  t0: {type: thermistor, preset: epcos_b57560g104f}
nets:
  plant_body: [plant.body, t0.body]
  t0_adc: [mega.PK5, t0.out]
)";
    auto board = test::thermal_board(yaml, "thermal_adc_probe_m2560");
    Adc& adc = board->mcu().adc();
    EXPECT_EQ(adc.channel_for_pin("PK6"), 14);
    EXPECT_EQ(adc.channel_for_pin("PF0"), 0);
    adc.set_voltage(14, 2.5);   // ADC = 2.5 * 1024 / 5 = 512
    adc.set_voltage(15, 5.0);   // full scale: 1024 -> clamped to 1023
    adc.set_voltage(0, 1.0);    // 204.8 -> 204
    board->run_for_seconds(0.02);
    Mcu& m = board->mcu();
    auto ch = [&](int i) { return test::read_u16_element(m, "adc_ch", i); };
    EXPECT_EQ(ch(0), 978);
    EXPECT_EQ(ch(1), 512);
    EXPECT_EQ(ch(2), 1023);
    EXPECT_EQ(ch(3), 204);
}

TEST(ThermistorAdc, Atmega328pChannelsAndTheBandgap) {
    const std::string yaml = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: e3d_v6, ambient: 25degC}
  t0: {type: thermistor, preset: ntc_100k_3950}
nets:
  plant_body: [plant.body, t0.body]
  t0_adc: [uno.PC0, t0.out]
)";
    auto board = test::thermal_board(yaml, "thermal_adc_probe_m328p", "uno");
    board->mcu().adc().set_voltage(5, 3.3);  // 3.3 * 1024 / 5 = 675.84 -> 675
    board->run_for_seconds(0.02);
    Mcu& m = board->mcu();
    auto ch = [&](int i) { return test::read_u16_element(m, "adc_ch", i); };
    EXPECT_EQ(ch(0), 978);
    EXPECT_EQ(ch(1), 675);
    // The 1.1 V bandgap against AVCC = 5 V: 1.1 * 1024 / 5 = 225.28 -> 225.
    EXPECT_EQ(ch(2), 225);
}

TEST(ThermistorAdc, Seed001ArrangementReadsEightBitsLeftAdjusted) {
    // seed 001's drive board: ATmega32, NTC on the lower leg of a divider on
    // ADC2 (PA2), AVCC reference, ADLAR, only ADCH read. The thesis picks the
    // fixed resistor equal to the NTC at the set point (190 degC); for a
    // 100k/3950 NTC that is 891.7 ohm (assumed part: the thesis names none).
    const std::string yaml = R"(
mcus:
  drive: {type: atmega32, clock: 16MHz}
parts:
  hotend: {type: thermal_plant, preset: e3d_v6, ambient: 25degC}
  heater: {type: heater, preset: cartridge_40w_12v}
  sensor: {type: thermistor, preset: ntc_100k_3950, pullup: 891.7ohm, leg: lower}
nets:
  hotend_body: [hotend.body, heater.body, sensor.body]
  sensor_adc: [drive.PA2, sensor.out]
  heater: [drive.PD7, heater.gate]
)";
    auto board = test::thermal_board(yaml, "thermal_adc_probe_m32", "drive");
    board->run_for_seconds(0.02);
    // 25 degC: V = 5 * 100000 / 100891.7 = 4.95581 V; ADC = 1014.95 -> 1014;
    // ADCH = 1014 >> 2 = 253.
    EXPECT_EQ(board->mcu().read_ram_u8("adc_high8"), 253);
    // The seed's heater PWM (OC2 = PD7, OCR2 = 77, clk/128): duty (77 + 1) / 256.
    board->run_for_seconds(1.0);
    auto& heater = board->part_as<Heater>("heater");
    const double duty = static_cast<double>(heater.on_cycles()) / static_cast<double>(board->mcu().cycle());
    EXPECT_NEAR(duty, 78.0 / 256.0, 0.005);
    // At the set point the divider is at half scale (V = 2.5 V: ADCH 128).
    auto& sensor = board->part_as<Thermistor>("sensor");
    EXPECT_NEAR(sensor.divider_volts(190.0), 2.5, 1e-3);
}

TEST(ThermistorAdc, NoiseIsSeededAndHasItsRms) {
    struct Run {
        std::vector<double> volts;
        std::vector<std::uint16_t> codes;  // what the firmware read, every 1 ms
    };
    auto run = [](const std::string& seed) {
        auto board = test::thermal_board(held_at("200degC", "epcos_b57560g104f", ", noise: 10mV, seed: " + seed),
                                         "thermal_adc_probe_m2560");
        Run out;
        board->mcu().adc().on_sample([&out](const Adc::Sample& s) {
            if (s.channel == 13) out.volts.push_back(s.volts);
        });
        for (int i = 0; i < 500; ++i) {
            board->run_for_seconds(0.001);
            out.codes.push_back(test::read_u16_element(board->mcu(), "adc_ch", 0));
        }
        return out;
    };
    const Run a = run("7"), b = run("7"), c = run("8");
    ASSERT_GT(a.volts.size(), 1000u);
    EXPECT_EQ(a.volts, b.volts);  // same seed, same samples
    EXPECT_EQ(a.codes, b.codes);
    EXPECT_NE(a.volts, c.volts);
    // Around the noiseless 0.52618 V (552.78 ohm under 4.7 kohm), 10 mV RMS.
    double sum = 0, sq = 0;
    for (double v : a.volts) {
        sum += v;
        sq += (v - 0.52618) * (v - 0.52618);
    }
    const double n = static_cast<double>(a.volts.size());
    EXPECT_NEAR(sum / n, 0.52618, 0.001);
    EXPECT_NEAR(std::sqrt(sq / n), 0.010, 0.0007);
    // The codes: 10 mV is 2.05 LSB, so they spread around 107.76 - 0.5 (truncation).
    double csum = 0;
    std::uint16_t lo = 1023, hi = 0;
    for (auto code : a.codes) {
        csum += code;
        lo = std::min(lo, code);
        hi = std::max(hi, code);
    }
    EXPECT_NEAR(csum / static_cast<double>(a.codes.size()), 107.26, 0.4);
    EXPECT_GE(hi - lo, 6);
}

TEST(ThermistorAdc, ANonAnalogPinIsRejectedWithFileAndLine) {
    const std::string yaml = R"(
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  plant: {type: thermal_plant, preset: e3d_v6}
  t0: {type: thermistor}
nets:
  plant_body: [plant.body, t0.body]
  t0_adc: [mega.PB4, t0.out]
)";
    try {
        test::thermal_board(yaml, "thermal_adc_probe_m2560");
        FAIL() << "PB4 accepted as an analog input";
    } catch (const BadInput& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("thermal-test.yaml:9"), std::string::npos) << what;
        EXPECT_NE(what.find("PB4"), std::string::npos) << what;
        EXPECT_NE(what.find("PK0..PK7 = ADC8..15"), std::string::npos) << what;
    }
}

}  // namespace
}  // namespace avrbench
