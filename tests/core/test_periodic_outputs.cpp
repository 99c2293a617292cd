// Compare outputs handed out as periodic waves (periph/timer/PeriodicOutput.hpp)
// instead of an event per edge: the waves, expanded, must be exactly the
// edges the timer model drives one by one, and the firmware must end in the
// same state, on every firmware the build makes.
#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "periph/timer/PeriodicOutput.hpp"
#include "support/EveryFirmware.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

TEST(PeriodicWave, HighCyclesAndLevelFollowTheEdges) {
    // A period of 256 cycles starting high, low from 64 on, high again at 256
    // (fast PWM, OCRnx = 63: high (63 + 1) of 256).
    PeriodicWave w;
    w.start = 1000;
    w.period = 256;
    w.start_level = true;
    w.edge_count = 2;
    w.edges[0] = {64, false};
    w.edges[1] = {256, true};
    EXPECT_EQ(w.high_cycles_per_period(), 64u);
    EXPECT_EQ(w.high_cycles_until(1000), 0u);
    EXPECT_EQ(w.high_cycles_until(1010), 10u);
    EXPECT_EQ(w.high_cycles_until(1000 + 100), 64u);
    EXPECT_EQ(w.high_cycles_until(1000 + 256 + 10), 64u + 10u);
    EXPECT_EQ(w.high_cycles_until(1000 + 3 * 256 + 200), 3 * 64u + 64u);
    EXPECT_TRUE(w.level_at(1000));
    EXPECT_TRUE(w.level_at(1063));
    EXPECT_FALSE(w.level_at(1064));
    EXPECT_FALSE(w.level_at(1255));
    EXPECT_TRUE(w.level_at(1256));
}

struct Edge {
    Cycle cycle;
    bool level;
    bool operator==(const Edge&) const = default;
};

// Every edge of one pin: the ones delivered, plus each wave's expanded.
class PinWaves final : public PeriodicOutputSink {
public:
    PinWaves(Mcu& mcu, Pin& pin, bool accept) : mcu_(mcu), pin_(pin) {
        pin_.on_change([this](Cycle cycle, bool level) { delivered_.push_back({cycle, level}); });
        if (accept) mcu_.set_periodic_output_sink(pin_, this);
    }
    ~PinWaves() override { mcu_.set_periodic_output_sink(pin_, nullptr); }
    PinWaves(const PinWaves&) = delete;
    PinWaves& operator=(const PinWaves&) = delete;

    bool begin_wave(const PeriodicWave& wave) override {
        waves_.push_back({wave, 0, false});
        return true;
    }
    void end_wave(Cycle at) override {
        waves_.back().end = at;
        waves_.back().ended = true;
    }
    const void* listener_param() const override { return &pin_; }

    // Edges at cycles < until, in order.
    std::vector<Edge> edges(Cycle until) const {
        std::vector<Edge> all;
        for (const Edge& e : delivered_) {
            if (e.cycle < until) all.push_back(e);
        }
        for (const Wave& w : waves_) {
            const Cycle end = w.ended ? std::min(w.end, until - 1) : until - 1;
            for (Cycle p = w.wave.start; p < end; p += w.wave.period) {
                for (std::size_t i = 0; i < w.wave.edge_count; ++i) {
                    const Cycle c = p + w.wave.edges[i].offset;
                    if (c <= end) all.push_back({c, w.wave.edges[i].level});
                }
            }
        }
        std::stable_sort(all.begin(), all.end(), [](const Edge& a, const Edge& b) { return a.cycle < b.cycle; });
        return all;
    }
    std::size_t waves_begun() const { return waves_.size(); }
    const PeriodicWave& first_wave() const { return waves_.front().wave; }

private:
    struct Wave {
        PeriodicWave wave;
        Cycle end;
        bool ended;
    };
    Mcu& mcu_;
    Pin& pin_;
    std::vector<Edge> delivered_;
    std::vector<Wave> waves_;
};

struct RunResult {
    Cycle cycle = 0;
    std::uint32_t pc = 0;
    std::vector<std::uint8_t> data;
    std::vector<std::vector<Edge>> edges;  // per pin
    std::size_t waves = 0;
    std::vector<PeriodicWave> first_waves;  // per pin; period 0 if none
};

McuOptions options_for(const std::string& name, const ElfImage& elf) {
    McuOptions options;
    test::set_board_mcu(name, elf, options);
    return options;
}

RunResult run(const std::string& name, bool accept_waves, Cycle cycles) {
    const ElfImage elf = ElfImage::load(test::firmware(name));
    Mcu mcu(elf, options_for(name, elf));
    std::vector<std::unique_ptr<PinWaves>> pins;
    for (char port = 'A'; port <= 'L'; ++port) {
        for (int bit = 0; bit < 8; ++bit) {
            try {
                Pin& pin = mcu.pin(std::string{'P', port, static_cast<char>('0' + bit)});
                pins.push_back(std::make_unique<PinWaves>(mcu, pin, accept_waves));
            } catch (const std::exception&) {
                break;  // no such port
            }
        }
    }
    mcu.run_until(cycles);
    mcu.settle_periodic_outputs();  // PINx shows the pins' levels of now
    RunResult r;
    r.cycle = mcu.cycle();
    r.pc = mcu.pc_bytes();
    r.data = mcu.data_memory();
    // The last cycles may hold an edge one side has delivered and the other not yet.
    for (const auto& p : pins) {
        r.edges.push_back(p->edges(cycles - 2000));
        r.waves += p->waves_begun();
        r.first_waves.push_back(p->waves_begun() > 0 ? p->first_wave() : PeriodicWave{0, 0, false, 0, {}});
    }
    return r;
}

TEST(PeriodicOutputs, WavesAreTheEdgesTheTimerDrivesOnEveryFirmware) {
    const auto names = test::all_firmware();
    ASSERT_GT(names.size(), 100u);
    std::size_t firmware_with_waves = 0;
    for (const auto& name : names) {
        const Cycle cycles = 16'000'000 / 50;  // 20 ms at 16 MHz
        const RunResult eager = run(name, false, cycles), waves = run(name, true, cycles);
        EXPECT_EQ(eager.waves, 0u) << name;
        EXPECT_EQ(eager.cycle, waves.cycle) << name;
        EXPECT_EQ(eager.pc, waves.pc) << name;
        EXPECT_TRUE(eager.data == waves.data) << name << ": registers, I/O or RAM differ";
        ASSERT_EQ(eager.edges.size(), waves.edges.size()) << name;
        for (std::size_t p = 0; p < eager.edges.size(); ++p) {
            EXPECT_TRUE(eager.edges[p] == waves.edges[p])
                << name << ": pin " << p << " has " << eager.edges[p].size() << " edges driven one by one, "
                << waves.edges[p].size() << " with waves";
        }
        if (waves.waves > 0) ++firmware_with_waves;
    }
    // The timer conformance firmware idles with PWM outputs running.
    EXPECT_GE(firmware_with_waves, 4u);
}

TEST(PeriodicOutputs, TheDatasheetsNarrowSpikeIsOneWave) {
    // tmr_fast_pwm on the ATmega328P: Timer0 mode 3 at clk/1, OC0A (PD6)
    // COM0A = 10, OCR0A = 0: "a narrow spike for each MAX+1 timer clock cycle"
    // (§15.7.3): a period of 256 cycles, high for one.
    const ElfImage elf = ElfImage::load(test::firmware("tmr_fast_pwm"));
    Mcu mcu(elf);
    PinWaves oc0a(mcu, mcu.pin("PD6"), true);
    mcu.run_until(40'000);
    ASSERT_GE(oc0a.waves_begun(), 1u);
    const PeriodicWave& w = oc0a.first_wave();
    EXPECT_EQ(w.period, 256u);
    EXPECT_EQ(w.high_cycles_per_period(), 1u);
    EXPECT_TRUE(w.start_level);  // set at BOTTOM, where a period starts
}

}  // namespace
}  // namespace avrbench
