#include "parts/Hd44780.hpp"

#include <cstdio>

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(Hd44780, "hd44780");

const FindingKind Hd44780::kWriteWhileBusy = FindingKind::declare(
    "lcd-write-while-busy", "an HD44780 got an instruction or data while still busy with the last one (lost)", Severity::Warning);
const FindingKind Hd44780::kReadNotModelled = FindingKind::declare(
    "lcd-read-not-modelled", "the firmware read an HD44780 (R/W high); the bench models writes only", Severity::Warning);

namespace {

// Execution times at f_OSC = 270 kHz (datasheet Table 6): clear display and
// return home 1.52 ms, every other instruction and a data write 37 us. After
// power-up the internal reset keeps the busy flag set for 10 ms ("Initializing
// by Internal Reset Circuit").
constexpr double kLongInstruction_s = 1.52e-3;
constexpr double kInstruction_s = 37e-6;
constexpr double kPowerUpBusy_s = 10e-3;

// DDRAM in two-line mode: line 1 at 0x00..0x27, line 2 at 0x40..0x67, 40
// characters each (datasheet Figure 5).
constexpr unsigned kLineLength = 40;

}  // namespace

std::vector<ParamSpec> Hd44780::param_specs() {
    using PT = ParamType;
    return {
        {.name = "geometry", .type = PT::Choice, .default_value = "20x4", .choices = {"16x2", "20x4", "16x4"},
         .help = "characters x lines (20x4: the Prusa MK3S and the RepRapDiscount Smart Controller)"},
        {.name = "screen_settle", .type = PT::Quantity, .dimension = Dimension::Time, .default_value = "20ms",
         .source = "assumed: a firmware draws a screen in one burst of writes, screens come at most every 50 ms or so",
         .help = "a screen is finished when no write came for this long", .min = 1e-6, .max = 10},
    };
}

Hd44780::Hd44780(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    const std::string geometry = params.text("geometry");
    columns_ = geometry == "20x4" ? 20 : 16;
    rows_ = geometry == "16x2" ? 2 : 4;
    settle_cycles_ = clock.cycles_from_seconds(params.quantity("screen_settle"));
    rs_pin_ = add_pin("rs", TerminalRole::Input);
    rw_pin_ = add_pin("rw", TerminalRole::Input);
    e_pin_ = add_pin("e", TerminalRole::Input);
    for (std::size_t i = 0; i < 8; ++i) d_pins_[i] = add_pin("d" + std::to_string(i), TerminalRole::Input);
    ddram_.fill(0x20);
    add_readout("writes", [this] { return static_cast<double>(writes_); });
    add_text_readout("lines", [this] { return lines(); });
}

void Hd44780::start() {
    busy_until_ = clock().cycle() + clock().cycles_from_seconds(kPowerUpBusy_s);
    e_level_ = connected(e_pin_) && input_level(e_pin_);
}

void Hd44780::on_input(std::size_t pin, bool level) {
    if (pin != e_pin_) return;
    const bool falling = e_level_ && !level;
    e_level_ = level;
    if (falling) latch();
}

// Data is latched on E's falling edge (datasheet Figure 25, bus timing).
void Hd44780::latch() {
    if (connected(rw_pin_) && input_level(rw_pin_)) {
        if (!read_reported_) {
            read_reported_ = true;
            report(kReadNotModelled, "E pulse with R/W high: the bench does not drive D0-D7 (busy flag reads are not modelled)");
        }
        return;
    }
    const bool rs = input_level(rs_pin_);
    std::uint8_t bus = 0;
    for (std::size_t i = 0; i < 8; ++i) {
        if (connected(d_pins_[i]) && input_level(d_pins_[i])) bus |= static_cast<std::uint8_t>(1u << i);
    }
    if (eight_bit_) {
        byte(rs, bus);
        return;
    }
    // Four bits on D4..D7: the high nibble first, then the low one.
    const auto nibble = static_cast<std::uint8_t>(bus >> 4);
    if (!have_high_nibble_) {
        high_nibble_ = nibble;
        have_high_nibble_ = true;
        return;
    }
    have_high_nibble_ = false;
    byte(rs, static_cast<std::uint8_t>((high_nibble_ << 4) | nibble));
}

void Hd44780::byte(bool rs, std::uint8_t value) {
    const Cycle now = clock().cycle();
    ++writes_;
    if (now < busy_until_) {
        if (lost_writes_++ == 0) {
            char text[160];
            std::snprintf(text, sizeof text, "%s 0x%02X came %.1f us before the controller was ready (datasheet Table 6); it is lost",
                          rs ? "data" : "instruction", value, static_cast<double>(busy_until_ - now) / clock().frequency_hz() * 1e6);
            report(kWriteWhileBusy, text);
        }
        return;
    }
    if (drawn_since_screen_ && now - last_write_cycle_ > settle_cycles_) note_screen();
    last_write_cycle_ = now;
    if (rs) {
        write_data(value);
    } else {
        instruction(value);
    }
    drawn_since_screen_ = true;
    note_activity();
}

void Hd44780::instruction(std::uint8_t v) {
    double busy_s = kInstruction_s;
    if ((v & 0x80) != 0) {  // set DDRAM address
        address_ = v & 0x7F;
        address_in_cgram_ = false;
    } else if ((v & 0x40) != 0) {  // set CGRAM address
        address_ = v & 0x3F;
        address_in_cgram_ = true;
    } else if ((v & 0x20) != 0) {  // function set: DL, N, F
        eight_bit_ = (v & 0x10) != 0;
        two_lines_ = (v & 0x08) != 0;
        have_high_nibble_ = false;
    } else if ((v & 0x10) != 0) {  // cursor or display shift
        if ((v & 0x08) != 0) {
            display_shift_ += (v & 0x04) != 0 ? 1 : -1;
        } else {
            move_address((v & 0x04) != 0 ? 1 : -1);
        }
    } else if ((v & 0x08) != 0) {  // display on/off control
        display_on_ = (v & 0x04) != 0;
        cursor_on_ = (v & 0x02) != 0;
        blink_on_ = (v & 0x01) != 0;
    } else if ((v & 0x04) != 0) {  // entry mode set
        increment_ = (v & 0x02) != 0;
        shift_display_ = (v & 0x01) != 0;
    } else if ((v & 0x02) != 0) {  // return home
        address_ = 0;
        address_in_cgram_ = false;
        display_shift_ = 0;
        busy_s = kLongInstruction_s;
    } else if (v == 0x01) {  // clear display
        ddram_.fill(0x20);
        address_ = 0;
        address_in_cgram_ = false;
        increment_ = true;
        display_shift_ = 0;
        busy_s = kLongInstruction_s;
    }
    busy_until_ = clock().cycle() + clock().cycles_from_seconds(busy_s);
}

void Hd44780::write_data(std::uint8_t v) {
    if (address_in_cgram_) {
        cgram_[address_ & 0x3F] = v;
        address_ = static_cast<std::uint8_t>((address_ + (increment_ ? 1 : -1)) & 0x3F);
    } else {
        ddram_[address_ & 0x7F] = v;
        move_address(increment_ ? 1 : -1);
        if (shift_display_) display_shift_ += increment_ ? -1 : 1;
    }
    busy_until_ = clock().cycle() + clock().cycles_from_seconds(kInstruction_s);
}

// The address counter over DDRAM: in two-line mode 0x27 is followed by 0x40
// and 0x67 by 0x00; in one-line mode 0x4F by 0x00 (datasheet "Address Counter").
void Hd44780::move_address(int delta) {
    if (two_lines_) {
        const unsigned line = address_ >= 0x40 ? 1 : 0;
        int pos = static_cast<int>(address_ - line * 0x40) + delta;
        unsigned next_line = line;
        if (pos >= static_cast<int>(kLineLength)) {
            pos = 0;
            next_line = 1 - line;
        } else if (pos < 0) {
            pos = kLineLength - 1;
            next_line = 1 - line;
        }
        address_ = static_cast<std::uint8_t>(next_line * 0x40 + static_cast<unsigned>(pos));
    } else {
        address_ = static_cast<std::uint8_t>((address_ + 80 + delta) % 80);
    }
}

// The A00 ROM (datasheet Table 4): ASCII from 0x20 to 0x7D, 0x7E right arrow,
// 0x7F left arrow, 0xDF degree sign; 0x00..0x0F the eight CGRAM characters
// (twice); the katakana and symbols above 0xA0 are shown as '?'.
std::string Hd44780::glyph(std::uint8_t code) const {
    if (code >= 0x20 && code <= 0x7D) return std::string(1, static_cast<char>(code));
    if (code == 0x7E) return "\u2192";
    if (code == 0x7F) return "\u2190";
    if (code == 0xDF) return "\u00B0";
    if (code < 0x10) return "#";
    return "?";
}

std::vector<std::string> Hd44780::lines() const {
    std::vector<std::string> out;
    for (unsigned r = 0; r < rows_; ++r) {
        std::string line;
        if (!display_on_ || (!two_lines_ && r > 0)) {
            line.assign(columns_, ' ');
            out.push_back(line);
            continue;
        }
        // Rows 3 and 4 continue lines 1 and 2 past the first `columns` characters.
        const unsigned base = (r % 2) * 0x40, offset = (r / 2) * columns_;
        for (unsigned c = 0; c < columns_; ++c) {
            const int pos = ((static_cast<int>(offset + c) - display_shift_) % static_cast<int>(kLineLength) + kLineLength) % kLineLength;
            line += glyph(ddram_[base + static_cast<unsigned>(pos)]);
        }
        out.push_back(line);
    }
    return out;
}

std::string Hd44780::text() const {
    std::string t;
    for (const auto& l : lines()) t += (t.empty() ? "" : "\n") + l;
    return t;
}

void Hd44780::note_screen() {
    screens_.push_back({last_write_cycle_, lines()});
    drawn_since_screen_ = false;
}

std::vector<Hd44780::Screen> Hd44780::screens() {
    if (drawn_since_screen_ && clock().cycle() - last_write_cycle_ > settle_cycles_) note_screen();
    std::vector<Screen> out = screens_;
    // A screen still being drawn when the run ends (or is asked) is the last.
    if (drawn_since_screen_) out.push_back({last_write_cycle_, lines()});
    return out;
}

std::string Hd44780::summary() {
    std::string out = "lcd        " + name() + ":";
    if (!display_on_) return out + " display off (" + std::to_string(writes_) + " writes)";
    for (const auto& l : lines()) out += " |" + l + "|";
    if (lost_writes_ != 0) out += " (" + std::to_string(lost_writes_) + " writes lost while busy)";
    return out;
}

}  // namespace avrbench
