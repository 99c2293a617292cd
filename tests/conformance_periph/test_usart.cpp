// USART0 baud rate, frame format, double-buffered transmitter and its
// UDRE/TXC/RXC flags and interrupts (firmware/conformance/peripherals/usart_modes).
#include <vector>

extern "C" {
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_irq.h>
}

#include "conformance_periph/PeriphSupport.hpp"
#include "periph/Fix.hpp"
#include "support/PinLog.hpp"

namespace avrbench {
namespace {

using test::kJmp;
using test::Markers;
using test::Part;

// Phases 1-3: U2X = 1, UBRR = 16: 8 * (16 + 1) = 136 cycles per bit
// (§20.3.1 Table 20-1); 8N1 = 10 bits per frame (§20.4).
constexpr Cycle kFrame8N1 = 10 * 8 * (16 + 1);  // 1360
// Phase 4: U2X = 0, UBRR = 103: 16 * 104 = 1664 cycles per bit; 8E2 =
// start + 8 data + parity + 2 stop = 12 bits.
constexpr Cycle kFrame8E2 = 12 * 16 * (103 + 1);  // 19968

class UsartModes : public ::testing::TestWithParam<const Part*> {};

TEST_P(UsartModes, TransmitterAndReceiverAreOffAfterReset) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    mcu.run_for(1000);
    // §20.11.3 (UCSRnB), ATmega32 "UCSRB": initial value 0x00.
    EXPECT_EQ(mcu.read_ram_u8("ucsrb_at_reset"), 0) << part.name;
}

TEST_P(UsartModes, PolledBytesLeaveExactlyOneFrameApartAndTxcEndsTheLast) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    Markers m(mcu);
    Uart& uart = mcu.uart(0);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 0, 100000));
    const auto& tx = uart.transmitted();
    ASSERT_GE(tx.size(), 4u);
    EXPECT_EQ(uart.transmitted_text().substr(0, 4), "ABCD");
    // §20.6: the second byte waits in the transmit buffer and follows the first
    // frame's stop bit at once; each later one as soon as UDRE lets it in.
    for (int i = 1; i < 4; ++i) EXPECT_EQ(tx[i].cycle - tx[i - 1].cycle, kFrame8N1) << part.name << " byte " << i;
    // TXC rises when the last frame is out; the polling loop (in, sbrs, rjmp)
    // and the sbi take a handful of cycles more.
    EXPECT_GE(m.rise(0) - tx[3].cycle, kFrame8N1) << part.name;
    EXPECT_LE(m.rise(0) - tx[3].cycle, kFrame8N1 + 10) << part.name;
}

TEST_P(UsartModes, UdreInterruptStreamsOneFramePerByteAndTxcInterruptsOnce) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    Markers m(mcu);
    Uart& uart = mcu.uart(0);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 1, 100000));
    const auto& tx = uart.transmitted();
    ASSERT_GE(tx.size(), 8u);
    EXPECT_EQ(uart.transmitted_text().substr(4, 4), "EFGH");
    for (int i = 5; i < 8; ++i) EXPECT_EQ(tx[i].cycle - tx[i - 1].cycle, kFrame8N1) << part.name << " byte " << i;
    // TXC at the end of H's frame wakes the sleeping core: wake-up (4; 2560: 5)
    // + response (4; 5) + jmp (3), then the ISR's sbi (§7.7.1).
    EXPECT_EQ(m.rise(1) - tx[7].cycle, kFrame8N1 + part.response + part.response + kJmp) << part.name;
    EXPECT_EQ(m.rises(1).size(), 1u) << part.name;
}

TEST_P(UsartModes, ReceivedFramesSetRxcOneFrameAfterTheirStart) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    Markers m(mcu);
    Uart& uart = mcu.uart(0);
    auto* u = reinterpret_cast<avr_uart_t*>(mcu.io_module("uart", '0'));
    std::vector<Cycle> rxc;
    std::pair<avr_t*, std::vector<Cycle>*> param{u->io.avr, &rxc};
    avr_irq_register_notify(
        u->rxc.irq + AVR_INT_IRQ_PENDING,
        [](avr_irq_t*, std::uint32_t value, void* p) {
            auto* pr = static_cast<std::pair<avr_t*, std::vector<Cycle>*>*>(p);
            if (value != 0 && (pr->second->empty() || pr->second->back() != pr->first->cycle)) {
                pr->second->push_back(pr->first->cycle);
            }
        },
        &param);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 3, 200000));
    mcu.run_for(100);
    const Cycle sent = mcu.cycle();
    uart.send("xyz");
    mcu.run_for(5 * kFrame8N1);
    const auto rx_bytes = mcu.read_ram("rx", 3);
    EXPECT_EQ(rx_bytes[0], 'x') << part.name;
    EXPECT_EQ(rx_bytes[1], 'y') << part.name;
    EXPECT_EQ(rx_bytes[2], 'z') << part.name;
    ASSERT_GE(rxc.size(), 3u) << part.name;
    // The host sends back to back: frame k is complete (k + 1) frames after the first start bit.
    for (int k = 0; k < 3; ++k) EXPECT_EQ(rxc[k] - sent, (k + 1) * kFrame8N1) << part.name << " byte " << k;
    avr_irq_unregister_notify(u->rxc.irq + AVR_INT_IRQ_PENDING, nullptr, &param);
}

TEST_P(UsartModes, ParityAndTwoStopBitsAtU2xOffMakeTwelveBitFrames) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    Markers m(mcu);
    Uart& uart = mcu.uart(0);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 3, 200000));
    uart.send("xyz");
    ASSERT_TRUE(test::run_until_rise(mcu, m, 4, 400000));
    EXPECT_EQ(uart.cycles_per_frame(), kFrame8E2) << part.name;
    const auto& tx = uart.transmitted();
    ASSERT_GE(tx.size(), 10u);
    EXPECT_EQ(uart.transmitted_text().substr(8, 2), "IJ");
    EXPECT_EQ(tx[9].cycle - tx[8].cycle, kFrame8E2) << part.name;
}

// TxDn and RxDn of USART0 (328P pinout: PD1/PD0, same on the m32; 2560
// pinout: PE1/PE0).
const char* txd_pin(const Part& part) { return &part == &test::kAtmega2560 ? "PE1" : "PD1"; }
const char* rxd_pin(const Part& part) { return &part == &test::kAtmega2560 ? "PE0" : "PD0"; }

// The levels a frame puts on the line, bit by bit (§20.4 Figure 20-4): start
// bit 0, data LSB first, the parity bit if any (even: XOR of the data bits,
// §20.4.1), stop bits 1.
std::vector<bool> frame_levels(std::uint8_t byte, bool even_parity, int stop_bits) {
    std::vector<bool> levels{false};
    bool parity = false;
    for (int bit = 0; bit < 8; ++bit) {
        const bool b = (byte >> bit) & 1;
        levels.push_back(b);
        parity ^= b;
    }
    if (even_parity) levels.push_back(parity);
    for (int i = 0; i < stop_bits; ++i) levels.push_back(true);
    return levels;
}

// Reads the pin in the middle of each bit of a frame starting at `start`.
std::vector<bool> sampled(const test::PinLog& log, Cycle start, Cycle cycles_per_bit, std::size_t bits) {
    std::vector<bool> levels;
    for (std::size_t k = 0; k < bits; ++k) levels.push_back(log.level_at(start + k * cycles_per_bit + cycles_per_bit / 2));
    return levels;
}

// A logic analyser on TxD sees every frame (§20.4 Figure 20-4): idle high
// once the transmitter is on, each bit one bit time long at the programmed
// rate: 8 (UBRR + 1) = 136 cycles at U2X = 1, UBRR = 16 and 16 (UBRR + 1) =
// 1664 at U2X = 0, UBRR = 103 (§20.3.1 Table 20-1).
TEST_P(UsartModes, TxdPinCarriesEveryFrameBitByBitAtTheProgrammedRate) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    Markers m(mcu);
    Uart& uart = mcu.uart(0);  // records from here on
    EXPECT_FALSE(mcu.pin(txd_pin(part)).is_output()) << part.name;  // §20.5: TxD is a port pin until TXEN
    test::PinLog txd(mcu, txd_pin(part));
    ASSERT_TRUE(test::run_until_rise(mcu, m, 3, 200000));
    uart.send("xyz");  // phase 3 waits for three bytes
    ASSERT_TRUE(test::run_until_rise(mcu, m, 4, 400000));
    EXPECT_TRUE(mcu.pin(txd_pin(part)).is_output()) << part.name;
    const auto& tx = uart.transmitted();
    ASSERT_GE(tx.size(), 10u);
    // §20.5: "the TxDn pin ... is overridden" by the transmitter: the line
    // is high before the first start bit.
    EXPECT_TRUE(txd.level_at(tx[0].cycle - 1)) << part.name;
    constexpr Cycle kBit8N1 = 8 * (16 + 1), kBit8E2 = 16 * (103 + 1);
    for (int i = 0; i < 8; ++i) {
        // The first falling edge of each frame is its start bit: at the cycle the bench stamps the byte with.
        EXPECT_FALSE(txd.level_at(tx[i].cycle)) << part.name << " byte " << i;
        EXPECT_TRUE(txd.level_at(tx[i].cycle - 1)) << part.name << " byte " << i;  // stop bit or idle before it
        EXPECT_EQ(sampled(txd, tx[i].cycle, kBit8N1, 10), frame_levels(tx[i].value, false, 1))
            << part.name << " byte " << i << " '" << static_cast<char>(tx[i].value) << "'";
    }
    for (int i = 8; i < 10; ++i) {
        EXPECT_EQ(sampled(txd, tx[i].cycle, kBit8E2, 12), frame_levels(tx[i].value, true, 2))
            << part.name << " byte " << i << " '" << static_cast<char>(tx[i].value) << "'";
    }
    // Every edge of the 8N1 bytes sits on the bit grid of its frame.
    for (const auto& e : txd.edges()) {
        if (e.cycle < tx[0].cycle || e.cycle >= tx[7].cycle + 10 * kBit8N1) continue;
        std::size_t frame = 0;
        while (frame + 1 < 8 && tx[frame + 1].cycle <= e.cycle) ++frame;
        EXPECT_EQ((e.cycle - tx[frame].cycle) % kBit8N1, 0u) << part.name << " edge at " << e.cycle;
    }
    // After the last frame the line idles high.
    EXPECT_TRUE(txd.level_at(mcu.cycle())) << part.name;
}

// Bytes a host sends are drawn on RxD as a logic analyser would see them
// from a real host: frames back to back from the moment they are sent.
TEST_P(UsartModes, HostBytesAreDrawnOnRxdAsFrames) {
    const Part& part = *GetParam();
    Mcu mcu = test::load("usart_modes", part);
    Markers m(mcu);
    ASSERT_TRUE(test::run_until_rise(mcu, m, 3, 200000));
    test::PinLog rxd(mcu, rxd_pin(part));
    mcu.run_for(100);
    const Cycle sent = mcu.cycle();
    mcu.uart(0).send("xyz");
    mcu.run_for(5 * kFrame8N1);
    constexpr Cycle kBit8N1 = 8 * (16 + 1);
    const std::string text = "xyz";
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(sampled(rxd, sent + k * kFrame8N1, kBit8N1, 10),
                  frame_levels(static_cast<std::uint8_t>(text[k]), false, 1))
            << part.name << " byte " << k;
    }
    EXPECT_TRUE(rxd.level_at(mcu.cycle())) << part.name;  // idle high after the last stop bit
}

INSTANTIATE_TEST_SUITE_P(Parts, UsartModes,
                         ::testing::Values(&test::kAtmega328p, &test::kAtmega2560, &test::kAtmega32), test::part_name);

}  // namespace
}  // namespace avrbench
