// The RAMPS 1.4 firmware in the Teacup/Marlin style
// (firmware/boards/ramps_teacup): thermistor sampling sees
// the fed voltage, the heater PWM duties are as commanded, the step interrupt
// moves X. The firmware runs unmodified: the bench only drives its pins, ADC
// input and serial line.
#include <cmath>
#include <string>
#include <vector>

#include "conformance_periph/PeriphSupport.hpp"
#include "periph/adc/Adc.hpp"

namespace avrbench {
namespace {

struct Edges {
    std::vector<Cycle> rises, falls;
    explicit Edges(Pin& pin) {
        pin.on_change([this](Cycle c, bool level) { (level ? rises : falls).push_back(c); });
    }
};

class Ramps : public ::testing::Test {
protected:
    Ramps() : mcu(ElfImage::load(test::firmware("ramps_teacup"))), uart(mcu.uart(0)) {}

    // Sends a command line and runs until the firmware has answered it.
    std::string command(const std::string& line, Cycle limit = 2'000'000) {
        const std::size_t before = uart.transmitted().size();
        uart.send(line + "\n");
        const Cycle end = mcu.cycle() + limit;
        while (mcu.cycle() < end) {
            mcu.run_for(2000);
            const std::string text = uart.transmitted_text();
            if (text.size() > before && text.back() == '\n') return text.substr(before);
        }
        return "(no answer)";
    }

    Mcu mcu;
    Uart& uart;
};

// ADC = VIN * 1024 / VREF (2560 §26.7), VREF = AVCC = 5 V; Marlin-style
// oversampling sums 16 conversions.
constexpr unsigned kOversample = 16;

TEST_F(Ramps, ThermistorSamplingSeesTheFedVoltage) {
    const int channel = mcu.adc().channel_for_pin("PK5");
    ASSERT_EQ(channel, 13);  // A13 = PK5 = ADC13 (2560 pinout)
    mcu.adc().set_voltage(channel, 2.5);
    mcu.run_for(200000);
    ASSERT_EQ(command("M105"), "ok T:" + std::to_string(kOversample * 512) + "\n");
    mcu.adc().set_voltage(channel, 1.25);
    // A new full reading: 16 samples, one per two 2048-cycle ticks, after the
    // one in progress: 2 * 32 * 2048 cycles.
    mcu.run_for(2 * 32 * 2048);
    EXPECT_EQ(mcu.read_ram_u16("current_raw"), kOversample * 256);
    EXPECT_EQ(command("M105"), "ok T:" + std::to_string(kOversample * 256) + "\n");
}

TEST_F(Ramps, HardwarePwmHeaterOnD10HasTheCommandedDuty) {
    Edges d10(mcu.pin("PB4"));
    mcu.run_for(20000);
    ASSERT_EQ(command("M42 P10 S64"), "ok\n");
    mcu.run_for(200000);
    ASSERT_GE(d10.rises.size(), 6u);
    // Timer2 fast PWM, clk/64 (2560 §20.7.3): period 256 * 64 = 16384 cycles;
    // OC2A set at BOTTOM, cleared at the match: high for OCR2A + 1 = 65 timer
    // clocks = 4160 cycles.
    const std::size_t n = d10.rises.size();
    EXPECT_EQ(d10.rises[n - 1] - d10.rises[n - 2], 256u * 64u);
    auto fall = std::lower_bound(d10.falls.begin(), d10.falls.end(), d10.rises[n - 2]);
    ASSERT_NE(fall, d10.falls.end());
    EXPECT_EQ(*fall - d10.rises[n - 2], 65u * 64u);
}

TEST_F(Ramps, SoftPwmOnD9HasTheCommandedDuty) {
    Edges d9(mcu.pin("PH6"));
    mcu.run_for(20000);
    ASSERT_EQ(command("M106 S100"), "ok\n");
    mcu.run_for(4 * 128 * 2048);
    ASSERT_GE(d9.rises.size(), 3u);
    // Soft PWM from the 2048-cycle Timer0 tick (256 * clk/8): a 128-tick period,
    // on for amount / 2 = 50 ticks.
    const std::size_t n = d9.rises.size();
    EXPECT_EQ(d9.rises[n - 1] - d9.rises[n - 2], 128u * 2048u);
    auto fall = std::lower_bound(d9.falls.begin(), d9.falls.end(), d9.rises[n - 2]);
    ASSERT_NE(fall, d9.falls.end());
    // The set and the clear are a few instructions apart in the ISR.
    EXPECT_NEAR(static_cast<double>(*fall - d9.rises[n - 2]), 50.0 * 2048.0, 16.0);
}

TEST_F(Ramps, StepInterruptMovesXAtTheTimerRateWithTheDriverEnabled) {
    Edges step(mcu.pin("PF0"));
    Edges enable(mcu.pin("PD7"));
    mcu.run_for(20000);
    ASSERT_EQ(command("G1 X100"), "ok\n");
    mcu.run_for(110 * 16000);
    ASSERT_EQ(step.rises.size(), 100u);
    EXPECT_EQ(mcu.read_ram_u16("x_position"), 100);
    EXPECT_TRUE(mcu.pin("PF1").level());  // DIR high: positive
    // Timer1 CTC, clk/8, OCR1A = 1999: a step interrupt every 2000 * 8 =
    // 16000 cycles. A step may wait for the instruction in progress or for the
    // temperature interrupt (both ISRs run with interrupts off, §7.7), so
    // single intervals vary by up to that ISR's length; the span is exact
    // within the same.
    for (std::size_t i = 1; i < step.rises.size(); ++i) {
        EXPECT_NEAR(static_cast<double>(step.rises[i] - step.rises[i - 1]), 16000.0, 200.0) << i;
    }
    EXPECT_NEAR(static_cast<double>(step.rises.back() - step.rises.front()), 99.0 * 16000.0, 200.0);
    // EN (active low) went low before the first step and high after the last.
    ASSERT_FALSE(enable.falls.empty());
    ASSERT_FALSE(enable.rises.empty());
    EXPECT_LT(enable.falls.back(), step.rises.front());
    EXPECT_GT(enable.rises.back(), step.rises.back());
}

}  // namespace
}  // namespace avrbench
