// Arduino sketches built against Debian's arduino-core-avr (firmware/arduino):
// real third-party code (wiring.c, HardwareSerial, WInterrupts, EEPROM) on the
// bench, each result checked against the core's documented arithmetic.
#include <gtest/gtest.h>

#include <sstream>

#include "boards/Board.hpp"
#include "periph/adc/Adc.hpp"
#include "mcu/Mcu.hpp"
#include "parts/SerialPeer.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

Mcu sketch(const std::string& name, const char* mcu_type = "atmega328p") {
    McuOptions o;
    o.mcu_type = mcu_type;
    o.frequency_hz = 16'000'000;  // boards.txt: uno/mega build.f_cpu=16000000L
    return Mcu(ElfImage::load(test::firmware(name)), o);
}

TEST(ArduinoCore, MillisReachesOneSecondAndDelayWaitsItsMilliseconds) {
    Mcu mcu = sketch("ard_millis_delay");
    Uart& serial = mcu.uart(0);  // records from here on
    std::vector<std::pair<Cycle, bool>> edges;
    mcu.pin("PB5").on_change([&edges](Cycle c, bool level) { edges.emplace_back(c, level); });
    mcu.run_for(16'000'000ull * 16 / 10);  // 1.6 s
    // wiring.c: Timer0 overflows every 64 * 256 = 16384 cycles (1024 us);
    // each adds 1 to millis() and 3 to a fraction that carries one more
    // millisecond at 125. The first overflow count whose millis() >= 1000:
    unsigned long millis = 0, fract = 0, overflows = 0;
    while (millis < 1000) {
        ++overflows;
        ++millis;
        fract += 3;
        if (fract >= 125) {
            fract -= 125;
            ++millis;
        }
    }
    ASSERT_GE(edges.size(), 7u);  // high at setup, low at 1 s, five toggles
    EXPECT_TRUE(edges[0].second);
    EXPECT_FALSE(edges[1].second);
    // Timer0 starts in init(), a few hundred cycles after reset; the loop
    // sees the overflow within a few cycles.
    const Cycle expected = overflows * 16384;
    EXPECT_GE(edges[1].first, expected);
    EXPECT_LT(edges[1].first, expected + 2000) << overflows << " overflows";
    // delay(100): at least 100 ms (micros() has a 4 us step), plus the
    // digitalRead/digitalWrite around it (a few microseconds). The first
    // interval also holds the Serial.println before the first delay.
    EXPECT_GE(edges[2].first - edges[1].first, 1'600'000u);
    for (std::size_t i = 3; i < 7; ++i) {
        const Cycle interval = edges[i].first - edges[i - 1].first;
        EXPECT_GE(interval, 1'600'000u) << "toggle " << i;
        EXPECT_LT(interval, 1'600'000u + 800u) << "toggle " << i;  // < 50 us over
    }
    const std::string out = serial.transmitted_text();
    EXPECT_EQ(out.substr(0, out.find('\r')), std::to_string(millis)) << out;
}

void expect_twenty_matches_at_every_phase(const char* elf, const char* mcu_type) {
    Mcu mcu = sketch(elf, mcu_type);
    Uart& serial = mcu.uart(0);
    mcu.run_for(16'000'000ull / 2);  // 8 x (20 ms + up to 2 ms) plus start-up
    // Counting up from TCNT1 <= 255 (8-bit PWM) to OCR1A = 1999 at clk/8:
    // the first match within 1 ms, then one every 1 ms: 20 in 20 ms.
    EXPECT_EQ(serial.transmitted_text(), "20 20 20 20 20 20 20 20\n") << elf;
}

TEST(ArduinoCore, Timer1SwitchedFromInitsPwmToCtcMatchesEveryMillisecondUno) {
    expect_twenty_matches_at_every_phase("ard_timer1_ctc_after_init", "atmega328p");
}

TEST(ArduinoCore, Timer1SwitchedFromInitsPwmToCtcMatchesEveryMillisecondMega) {
    expect_twenty_matches_at_every_phase("ard_timer1_ctc_after_init_mega", "atmega2560");
}

TEST(ArduinoCore, InputPullupReadsHighAndAttachInterruptCountsEveryChange) {
    Mcu mcu = sketch("ard_input_pullup_interrupt");
    Uart& serial = mcu.uart(0);
    mcu.run_for(16'000);  // 1 ms: setup() has printed
    mcu.run_for(160'000);
    EXPECT_EQ(serial.transmitted_text(), "pullup 1 0\r\n");  // pull-up on; off (floating: the bench's 0)
    // Drive D2 low then high: two changes, two interrupts.
    mcu.pin("PD2").drive(false);
    mcu.run_for(16'000);
    mcu.pin("PD2").drive(true);
    mcu.run_for(16'000);
    serial.send("?");
    mcu.run_for(160'000);
    EXPECT_EQ(serial.transmitted_text(), "pullup 1 0\r\nedges 2\r\n");
}

TEST(ArduinoCore, EepromLibraryWritesAndReadsBack) {
    Mcu mcu = sketch("ard_eeprom");
    Uart& serial = mcu.uart(0);
    // 16 writes of 3.4 ms each (328P Table 8-2, erase and write): ~55 ms.
    mcu.run_for(16'000'000ull / 10);
    // Sum of 3a + 7 for a = 0..15 = 3 * 120 + 16 * 7 = 472.
    EXPECT_EQ(serial.transmitted_text(), "eeprom 472 472\r\n");
}

// analogRead(A0 + i) on every analog input: the core selects the channel
// (with MUX5 in ADCSRB for A8-A15 on the Mega, wiring_analog.c) and returns
// ADC = VIN * 1024 / VREF with the default AVCC reference (§24.7; 5 V here).
// Each input gets a different code, half an LSB above its transition so the
// bench's millivolt rounding cannot move it.
void expect_every_analog_input(const char* elf, const char* mcu_type, int inputs, const char* first_pin_port) {
    Mcu mcu = sketch(elf, mcu_type);
    Uart& serial = mcu.uart(0);
    std::vector<int> codes;
    for (int i = 0; i < inputs; ++i) {
        const int code = 37 + 60 * i;
        codes.push_back(code);
        // UNO A0-A5 = PC0-PC5 = ADC0-5; Mega A0-A7 = PF0-7 = ADC0-7, A8-A15 = PK0-7 = ADC8-15.
        const std::string pin = std::string(i < 8 ? first_pin_port : "PK") + static_cast<char>('0' + i % 8);
        mcu.adc().set_voltage(mcu.adc().channel_for_pin(pin), (code + 0.5) * 5.0 / 1024.0);
    }
    mcu.run_for(16'000'000ull / 20);  // 50 ms: setup and one round (< 20 conversions of 104 us)
    std::ostringstream expected;
    for (int i = 0; i < inputs; ++i) expected << codes[i] << (i + 1 < inputs ? ' ' : '\n');
    const std::string out = serial.transmitted_text();
    EXPECT_EQ(out.substr(0, out.find('\n') + 1), expected.str()) << elf;
}

TEST(ArduinoCore, AnalogReadOnEveryInputUno) { expect_every_analog_input("ard_analog_read", "atmega328p", 6, "PC"); }
TEST(ArduinoCore, AnalogReadOnEveryInputMega) {
    expect_every_analog_input("ard_analog_read_mega", "atmega2560", 16, "PF");
}

// SoftwareSerial at 9600 baud, bit-banged by the library's tuned delay loops,
// against a pin-level serial peer on D10/D11.
TEST(ArduinoCore, SoftwareSerialTalksToAPinLevelPeer) {
    const std::string board_text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  peer: {type: serial_peer, baud: 9600}
nets:
  to_sketch: [peer.tx, uno.PB2]
  from_sketch: [uno.PB3, peer.rx]
)";
    Board board(parse_board_text(board_text, "software-serial.yaml"), {{"uno", test::firmware("ard_software_serial")}});
    auto& peer = board.part_as<SerialPeer>("peer");
    // One byte every 3 ms: SoftwareSerial transmits with interrupts off, so a
    // byte arriving while it echoes the previous one is lost or garbled (the
    // library's documented half-duplex limit, the same on a real UNO); 3 ms
    // leaves room for 1.04 ms in and 1.04 ms out.
    const std::string hello = "hello";
    for (std::size_t i = 0; i < hello.size(); ++i) {
        peer.send(hello.substr(i, 1), board.mcu().cycles_from_seconds(0.020 + 0.003 * static_cast<double>(i)));
    }
    board.run_for_seconds(0.05);
    // println: "ready\r\n"; then each byte echoed in upper case.
    EXPECT_EQ(peer.received(), "ready\r\nHELLO");
    // SoftwareSerial's delays are tuned for 16 MHz: its edges sit on the
    // 104.17 us grid within the 5 % the peer allows.
    EXPECT_LT(peer.worst_edge_error_bits(), 0.05);
    EXPECT_GT(peer.worst_edge_error_bits(), 0.0);  // measured, not skipped
    EXPECT_TRUE(board.findings().empty()) << board.findings().front().describe();
}

// A whole serial line at pin level: the host talks to a Mega's Serial, the
// Mega's Serial1 TX1 pin (PD3) drives a wire to the UNO's SoftwareSerial RX
// (PB2), the UNO's TX (PB3) drives a wire to the Mega's RX1 (PD2). Nothing
// between the two MCUs but two nets: the Mega's USART1 transmitter must toggle
// its pin and its receiver must sample the line.
TEST(ArduinoCore, HardwareSerialAndSoftwareSerialTalkOverTwoWires) {
    const std::string board_text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
  mega: {type: atmega2560, clock: 16MHz}
nets:
  mega_to_uno: [mega.PD3, uno.PB2]
  uno_to_mega: [uno.PB3, mega.PD2]
)";
    Board board(parse_board_text(board_text, "serial-bridge.yaml"),
                {{"uno", test::firmware("ard_software_serial")}, {"mega", test::firmware("ard_serial_bridge_mega")}});
    Uart& host = board.mcu("mega").uart(0);
    // One byte every 3 ms, for SoftwareSerial's half-duplex limit (see above).
    const std::string hello = "hello";
    for (std::size_t i = 0; i < hello.size(); ++i) {
        board.run_for_seconds(i == 0 ? 0.020 : 0.003);
        host.send(hello.substr(i, 1));
    }
    board.run_for_seconds(0.010);
    // The bridge's banner, then the UNO's "ready\r\n" that came in on Serial1
    // while the banner was still going out, then each byte echoed upper case.
    EXPECT_EQ(host.transmitted_text(), "bridge\r\nready\r\nHELLO");
    EXPECT_EQ(board.mcu("mega").uart(1).line_framing_errors(), 0u);
    EXPECT_TRUE(board.findings().empty()) << board.findings().front().describe();
}

// The Wire library on two MCUs: an UNO master (A4 = PC4 SDA, A5 = PC5 SCL)
// and a Mega slave at address 8 (D20 = PD1 SDA, D21 = PD0 SCL), with only
// the internal pull-ups twi_init() switches on, as two boards joined by
// three wires. Expected text from the sketches and Wire's API: beginTransmission/
// endTransmission returns 0 when every byte was ACKed; requestFrom returns
// the count received; onReceive runs at the STOP with the bytes written.
TEST(ArduinoCore, WireMasterAndSlaveOnTwoMcus) {
    const std::string board_text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
  mega: {type: atmega2560, clock: 16MHz}
nets:
  sda: [uno.PC4, mega.PD1]
  scl: [uno.PC5, mega.PD0]
)";
    Board board(parse_board_text(board_text, "wire-pair.yaml"),
                {{"uno", test::firmware("ard_wire_master")}, {"mega", test::firmware("ard_wire_slave_mega")}});
    Uart& master_serial = board.mcu("uno").uart(0);
    Uart& slave_serial = board.mcu("mega").uart(0);
    // Five rounds 20 ms apart (plus the serial printing): done by 0.15 s.
    board.run_for_seconds(0.15);
    std::string master_expected = "master\r\n";
    std::string slave_expected = "slave\r\n";
    for (int round = 0; round < 5; ++round) {
        const std::string n = std::to_string(round);
        // The slave has counted round + 1 writes when the read comes.
        master_expected += "tx 0\r\nrx 6 ok#" + std::to_string(round + 1) + "..\r\n";
        slave_expected += "got 3 n=" + n + "\r\n";
    }
    master_expected += "done\r\n";
    EXPECT_EQ(master_serial.transmitted_text(), master_expected);
    EXPECT_EQ(slave_serial.transmitted_text(), slave_expected);
    EXPECT_TRUE(board.findings().empty()) << board.findings().front().describe();
}

}  // namespace
}  // namespace avrbench
