// A character LCD on an HD44780U controller (Hitachi HD44780U datasheet,
// ADE-207-272(Z) '99.9 Rev. 0.0): the 4- and 8-bit buses (data latched on
// E's falling edge), the instruction set with its execution times at the
// 270 kHz oscillator (Table 6: 37 us, clear and home 1.52 ms), DDRAM with the
// 16x2, 20x4 and 16x4 geometries, CGRAM, the A00 character ROM. Writing while
// the controller is busy is a finding and the write is lost, as the
// datasheet says ("the next instruction will not be accepted"). What it
// shows is an observable: text() now, screens() over time.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"

namespace avrbench {

class Hd44780 final : public Part {
public:
    static const FindingKind kWriteWhileBusy;  // lcd-write-while-busy
    static const FindingKind kReadNotModelled;  // lcd-read-not-modelled
    static std::vector<ParamSpec> param_specs();

    Hd44780(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "hd44780"; }
    void start() override;
    std::string summary() override;

    // The visible text, one string per line (the A00 ROM mapped to UTF-8:
    // ASCII, 0x7E right arrow, 0x7F left arrow, 0xDF degree sign; CGRAM
    // characters 0..7 as the digits in a box is not text: shown as '#').
    std::vector<std::string> lines() const;
    std::string text() const;  // lines joined with '\n'
    bool display_on() const { return display_on_; }
    // Each screen the firmware drew: the text once no write came for
    // `screen_settle` (a burst of writes is one screen), with the time of its
    // last write; the last entry may be a screen still being drawn.
    struct Screen {
        Cycle cycle;
        std::vector<std::string> lines;
    };
    std::vector<Screen> screens();
    std::vector<TextScreen> text_screens() override {
        std::vector<TextScreen> out;
        for (auto& s : screens()) out.push_back({s.cycle, std::move(s.lines)});
        return out;
    }
    std::uint64_t writes() const { return writes_; }

private:
    void on_input(std::size_t pin, bool level) override;
    void latch();
    void byte(bool rs, std::uint8_t value);
    void instruction(std::uint8_t value);
    void write_data(std::uint8_t value);
    void move_address(int delta);
    std::string glyph(std::uint8_t code) const;
    void note_screen();

    std::size_t rs_pin_, rw_pin_, e_pin_;
    std::array<std::size_t, 8> d_pins_{};
    unsigned columns_, rows_;
    Cycle settle_cycles_;

    bool eight_bit_ = true;      // DL; at power-up the interface is 8 bits
    bool two_lines_ = false;     // N
    bool have_high_nibble_ = false;
    std::uint8_t high_nibble_ = 0;
    bool e_level_ = false;
    Cycle busy_until_ = 0;
    std::array<std::uint8_t, 128> ddram_{};
    std::array<std::uint8_t, 64> cgram_{};
    std::uint8_t address_ = 0;   // AC
    bool address_in_cgram_ = false;
    bool increment_ = true;      // I/D
    bool shift_display_ = false; // S
    int display_shift_ = 0;
    bool display_on_ = false, cursor_on_ = false, blink_on_ = false;
    std::uint64_t writes_ = 0, lost_writes_ = 0;
    Cycle last_write_cycle_ = 0;
    bool drawn_since_screen_ = false;
    bool read_reported_ = false;
    std::vector<Screen> screens_;
};

}  // namespace avrbench
