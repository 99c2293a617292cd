// The serial_host part: a host on the firmware's TX and RX nets, at byte
// level where they are a USART's pins and at bit level elsewhere; and the
// deprecated `serial:` section read as one.
#include <gtest/gtest.h>

#include "boards/BoardFile.hpp"
#include "core/Notice.hpp"
#include "periph/ports/Pin.hpp"
#include "periph/usart/Uart.hpp"
#include "parts/SerialHost.hpp"
#include "support/Paths.hpp"
#include "run/Bench.hpp"

namespace avrbench {
namespace {

// An UNO with a serial_host whose rx joins `firmware_tx` and tx `firmware_rx`.
std::string host_board(const std::string& host_params, const std::string& firmware_tx, const std::string& firmware_rx) {
    return R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  host: {type: serial_host)" + host_params + R"(}
nets:
  from_firmware: [uno.)" + firmware_tx + R"(, host.rx]
  to_firmware: [host.tx, uno.)" + firmware_rx + R"(]
)";
}

// SoftwareSerial's pins in firmware/arduino/software_serial_lines.cpp: D11
// (PB3) transmits, D10 (PB2) receives.
std::string soft_serial_board(const std::string& host_params) { return host_board(host_params, "PB3", "PB2"); }

TEST(SerialHost, OnAUsartsPinsItWorksAtByteLevelAndDrawsItsFramesOnTheNet) {
    Bench bench(test::source_path("bench/boards/arduino-uno.yaml"), test::firmware("uart_echo"));
    const SerialPort& port = bench.serial_port();
    ASSERT_NE(port.connector->usart(), nullptr);
    EXPECT_EQ(port.connector->usart()->index(), 0);
    EXPECT_EQ(port.connector->link_text(), "USART0 (PD1/PD0)");
    // An adapter's TX idles at mark from power-on (ATmega328P §20.4).
    Pin& rxd = bench.board().pin("uno.PD0");
    EXPECT_TRUE(rxd.level());
    std::vector<bool> edges;
    rxd.on_change([&edges](Cycle, bool level) { edges.push_back(level); });
    bench.run_for(0.002);  // uart_echo's receiver is on
    bench.serial().send("U");
    bench.run_for(0.002);
    // 'U' = 0x55 sent LSB first: start 0, then 1 0 1 0 1 0 1 0, stop 1 - a
    // change at every one of the 10 bit boundaries.
    EXPECT_EQ(edges.size(), 10u);
    EXPECT_NE(bench.serial().transmitted_text().find('U'), std::string::npos) << bench.serial().transmitted_text();
}

TEST(SerialHost, OnOtherPinsItWorksAtBitLevel) {
    Bench bench(parse_board_text(soft_serial_board(", baud: 9600"), "soft-serial.yaml"),
                {{"uno", test::firmware("ard_software_serial_lines")}});
    const SerialPort& port = bench.serial_port();
    EXPECT_EQ(port.connector->usart(), nullptr);
    EXPECT_EQ(port.connector->link_text(), "PB3/PB2 at 9600 baud");
    UartHostOptions o = default_host_options(port);
    o.startup = Startup::WaitForBanner;  // the sketch listens once setup() has run
    o.banner_contains = "start";
    UartHost& host = bench.host("", o);
    host.add_lines("G1 x10\nm114\n");
    EXPECT_EQ(bench.run_until_idle(3.0), IdleResult::Idle) << host.failure_message() << host.tail(10);
    EXPECT_EQ(host.lines_acknowledged(), 2u);
    std::vector<std::string> received;
    for (const auto& e : host.transcript()) {
        if (e.direction == Direction::Received) received.push_back(e.text);
    }
    // The sketch's protocol: "start", then per line "echo:" + the line in upper case, and "ok".
    const std::vector<std::string> expected{"start", "echo:G1 X10", "ok", "echo:M114", "ok"};
    EXPECT_EQ(received, expected);
    EXPECT_TRUE(bench.findings().empty());
}

TEST(SerialHost, ABitLevelHostAtTwiceTheBaudReadsFramingErrors) {
    // At 19200 the host reads a 9600-baud frame's stop bit 9.5 of its bits =
    // 4.75 of the sketch's bits after the start: data bit 3 of 's' (0x73),
    // which is 0 - a framing error on the first byte of "start".
    Bench bench(parse_board_text(soft_serial_board(", baud: 19200"), "soft-serial-fast.yaml"),
                {{"uno", test::firmware("ard_software_serial_lines")}});
    bench.run_for(0.2);
    const auto findings = bench.findings();
    ASSERT_FALSE(findings.empty());
    EXPECT_EQ(findings.front().kind, SerialHost::kHostLineFraming);
    EXPECT_EQ(bench.serial().transmitted_text().find("start"), std::string::npos);
}

TEST(SerialHost, ALineWithoutTheMcuIsAnErrorWithTheFileAndLine) {
    const std::string text = R"(
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  peer: {type: serial_peer}
  host: {type: serial_host}
nets:
  talk: [peer.tx, host.rx]
  to_uno: [host.tx, uno.PD0]
)";
    try {
        Bench bench(parse_board_text(text, "no-mcu-rx.yaml"), {{"uno", test::firmware("uart_echo")}});
        FAIL() << "no error";
    } catch (const BadInput& e) {
        EXPECT_STREQ(e.what(), "no-mcu-rx.yaml:6: part 'host' (serial_host): rx shares no net with a pin of MCU 'uno' "
                               "(rx joins the firmware's TX pin, tx its RX pin)");
    }
}

TEST(SerialHost, AnUnosOneKiloOhmLetsASketchDriveItsRxPin) {
    // busy_poll makes PD0..PD7 outputs and counts on them. On an UNO the
    // 16U2's TX reaches PD0 through 1 kohm (RN4, the UNO R3 schematic), so
    // the sketch wins without a fight; a host wired directly contends.
    auto contentions = [](const std::string& host_params) {
        // ATmega328P Table 14-9: TXD PD1, RXD PD0.
        Bench bench(parse_board_text(host_board(host_params, "PD1", "PD0"), "busy.yaml"), {{"uno", test::firmware("busy_poll")}});
        bench.run_for(0.001);
        std::size_t n = 0;
        for (const auto& f : bench.findings()) n += f.kind == Net::kNetContention ? 1 : 0;
        return n;
    };
    EXPECT_EQ(contentions(""), 0u);
    EXPECT_GT(contentions(", series_resistance: 0ohm"), 0u);
}

TEST(SerialHost, TheOldSerialSectionIsASerialHostOnTheUsartsPinsWithADeprecationLine) {
    std::vector<std::string> notices;
    const NoticeSink previous = set_notice_sink([&notices](const std::string& line) { notices.push_back(line); });
    const BoardSpec spec = parse_board_text(R"(mcus:
  uno: {type: atmega328p, clock: 16MHz}
serial:
  usb: {mcu: uno, usart: 0, flow: character_counting, family: grbl, line_timeout: 3s}
)",
                                            "old-serial.yaml");
    set_notice_sink(previous);
    EXPECT_TRUE(spec.serial.empty());
    const PartDecl* part = spec.find_part("usb");
    ASSERT_NE(part, nullptr);
    EXPECT_EQ(part->type, "serial_host");
    std::map<std::string, std::string> params;
    for (const auto& p : part->params) params[p.name] = p.value;
    EXPECT_EQ(params["family"], "grbl");
    EXPECT_EQ(params["flow"], "character_counting");
    EXPECT_EQ(params["line_timeout"], "3s");
    // ATmega328P Table 14-9: TXD is PD1, RXD is PD0.
    ASSERT_EQ(spec.nets.size(), 2u);
    EXPECT_EQ(spec.nets[0].name, "usb_rx");
    EXPECT_EQ(spec.nets[0].endpoints[0].text(), "uno.PD1");
    EXPECT_EQ(spec.nets[0].endpoints[1].text(), "usb.rx");
    EXPECT_EQ(spec.nets[1].endpoints[0].text(), "usb.tx");
    EXPECT_EQ(spec.nets[1].endpoints[1].text(), "uno.PD0");
    ASSERT_EQ(notices.size(), 1u);
    EXPECT_EQ(notices[0].rfind("old-serial.yaml:4: 'serial:' is deprecated", 0), 0u) << notices[0];
    // And it runs: the job goes through the part.
    Bench bench(spec, {{"uno", test::firmware("host_peer_grbl")}});
    UartHost& host = bench.host();
    host.add_line("G1 X1");
    EXPECT_EQ(bench.run_until_idle(5.0), IdleResult::Idle) << host.failure_message() << host.tail(10);
    EXPECT_EQ(host.oks(), 1u);
}

}  // namespace
}  // namespace avrbench
