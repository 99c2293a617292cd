#include "parts/SpiBus.hpp"

#include <cstdio>

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "parts/Part.hpp"
#include "periph/ports/McuPins.hpp"
#include "wiring/Net.hpp"

namespace avrbench {

const FindingKind kSpiModeMismatch = FindingKind::declare(
    "spi-mode-mismatch", "the SPI master shifted a byte in a mode or bit order the slave's datasheet does not use", Severity::Warning);
const FindingKind kSpiClockTooFast = FindingKind::declare(
    "spi-clock-too-fast", "the SPI clock was faster than the selected slave's datasheet allows", Severity::Warning);
const FindingKind kSpiBusContention = FindingKind::declare(
    "spi-bus-contention", "two SPI slaves were selected at once and both drove MISO", Severity::Error);

namespace {

std::string mcu_pin_on(Part& part, std::size_t pin) {
    const Net* net = part.pin(pin).net();
    if (net == nullptr) return "";
    for (const Terminal* t : net->terminals()) {
        if (t->mcu_pin() != nullptr && t->clock_mcu() == &part.clock()) return t->mcu_pin()->name();
    }
    return "";
}

}  // namespace

void attach_spi_slave(Part& part, std::size_t sck, std::size_t mosi, std::size_t miso, SpiSlave& slave) {
    Mcu& mcu = part.clock();
    const auto pins = spi_pins(mcu.mcu_type());
    if (!pins) throw part_error(part.name(), "the bench does not know the SPI pins of " + mcu.mcu_type());
    const struct {
        std::size_t pin;
        const std::string& wanted;
        const char* what;
    } needs[] = {{sck, pins->sck, "SCK"}, {mosi, pins->mosi, "MOSI"}, {miso, pins->miso, "MISO"}};
    for (const auto& n : needs) {
        const std::string on = mcu_pin_on(part, n.pin);
        if (on != n.wanted) {
            throw part_error(part.name(), "pin '" + part.pin(n.pin).name() + "' must share a net with " + n.wanted + " (" +
                                              n.what + " of MCU '" + mcu.name() + "', " + mcu.mcu_type() + ")" +
                                              (on.empty() ? std::string(", it joins no pin of that MCU") : ", not " + on));
        }
    }
    Spi* spi = mcu.spi();
    if (spi == nullptr) throw part_error(part.name(), "MCU '" + mcu.name() + "' has no SPI module in simavr");
    spi->attach(slave);
}

std::string spi_contention_detail(const std::string& others) {
    return "selected together with " + others + ": their outputs fought on MISO (a chip select left floating or low?)";
}

std::string spi_mode_problem(const SpiTransfer& t, const SpiLimits& limits) {
    if (t.mode() == limits.mode && t.lsb_first == limits.lsb_first) return "";
    char text[200];
    std::snprintf(text, sizeof text, "byte 0x%02X shifted in SPI mode %d, %s first; the slave uses mode %d, %s first (%s)", t.mosi,
                  t.mode(), t.lsb_first ? "LSB" : "MSB", limits.mode, limits.lsb_first ? "LSB" : "MSB", limits.source.c_str());
    return text;
}

std::string spi_clock_problem(const SpiTransfer& t, const SpiLimits& limits) {
    if (limits.max_sck_hz <= 0 || t.sck_hz <= limits.max_sck_hz * (1 + 1e-9)) return "";
    char text[200];
    std::snprintf(text, sizeof text, "SCK at %.4g MHz; the slave allows at most %.4g MHz (%s)", t.sck_hz / 1e6,
                  limits.max_sck_hz / 1e6, limits.source.c_str());
    return text;
}

}  // namespace avrbench
