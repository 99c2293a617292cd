#include "parts/SpiFlash.hpp"

#include <algorithm>
#include <cstdio>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "mcu/Mcu.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(SpiFlash, "spi_flash");

const FindingKind SpiFlash::kWriteNotEnabled = FindingKind::declare(
    "flash-write-not-enabled", "a program, erase or status write reached an SPI flash without Write Enable first (ignored)",
    Severity::Warning);
const FindingKind SpiFlash::kCommandWhileBusy = FindingKind::declare(
    "flash-command-while-busy", "an SPI flash got a command other than Read Status while busy or powered down (ignored)",
    Severity::Warning);
const FindingKind SpiFlash::kUnknownCommand = FindingKind::declare(
    "flash-unknown-command", "an SPI flash got an instruction it does not have", Severity::Warning);

namespace {

// Instructions (W25X20CL datasheet §8.2, as Prusa-Firmware's xflash.c names them).
enum : std::uint8_t {
    kWriteEnable = 0x06, kWriteDisable = 0x04, kReadStatus = 0x05, kWriteStatus = 0x01, kRead = 0x03,
    kFastRead = 0x0B, kPageProgram = 0x02, kSectorErase = 0x20, kBlock32Erase = 0x52, kBlock64Erase = 0xD8,
    kChipErase = 0xC7, kChipErase2 = 0x60, kPowerDown = 0xB9, kReleasePowerDown = 0xAB, kManufacturerDevice = 0x90,
    kJedecId = 0x9F, kUniqueId = 0x4B,
};
constexpr std::uint8_t kBusy = 0x01, kWel = 0x02;
constexpr std::size_t kPageBytes = 256;

}  // namespace

std::vector<ParamSpec> SpiFlash::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "size", .type = PT::Integer, .default_value = "262144",
         .source = "W25X20CL: 2 Mbit = 256 KB", .help = "bytes (a power of two from 64 KB to 16 MB)", .min = 65536, .max = 16777216},
        {.name = "manufacturer_id", .type = PT::Integer, .default_value = "239",
         .source = "Winbond 0xEF (Prusa-Firmware xflash.c _MFRID_W25X20CL)", .help = "0x90's first byte, 0x9F's first", .min = 0, .max = 255},
        {.name = "device_id", .type = PT::Integer, .default_value = "17",
         .source = "W25X20CL 0x11 (Prusa-Firmware xflash.c _DEVID_W25X20CL)", .help = "0x90's second byte, 0xAB's", .min = 0, .max = 255},
        {.name = "memory_type", .type = PT::Integer, .default_value = "48",
         .source = "W25X series 0x30 (JEDEC ID EF 30 12 for the W25X20CL)", .help = "0x9F's second byte", .min = 0, .max = 255},
        {.name = "page_program_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "0.8ms",
         .source = "assumed: a W25X-family typical tPP", .help = "BUSY after a page program", .min = 0, .max = 10},
        {.name = "sector_erase_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "30ms",
         .source = "assumed: a W25X-family typical tSE (4 KB)", .help = "BUSY after a sector erase", .min = 0, .max = 10},
        {.name = "block_erase_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "150ms",
         .source = "assumed: a W25X-family typical tBE (32/64 KB)", .help = "BUSY after a block erase", .min = 0, .max = 100},
        {.name = "chip_erase_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "1s",
         .source = "assumed: a W25X-family typical tCE for 2 Mbit", .help = "BUSY after a chip erase", .min = 0, .max = 1000},
        {.name = "image", .type = PT::Text,
         .help = "a file with the starting contents (shorter: the rest erased); never written to"},
    };
}

SpiFlash::SpiFlash(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    const long long size = params.integer("size");
    if ((size & (size - 1)) != 0) throw part_error(this->name(), "size must be a power of two");
    manufacturer_ = static_cast<std::uint8_t>(params.integer("manufacturer_id"));
    device_ = static_cast<std::uint8_t>(params.integer("device_id"));
    memory_type_ = static_cast<std::uint8_t>(params.integer("memory_type"));
    // JEDEC capacity byte: log2 of the size in bytes (0x12 for 256 KB).
    capacity_ = static_cast<std::uint8_t>(__builtin_ctzll(static_cast<unsigned long long>(size)));
    page_program_s_ = params.quantity("page_program_time");
    sector_erase_s_ = params.quantity("sector_erase_time");
    block_erase_s_ = params.quantity("block_erase_time");
    chip_erase_s_ = params.quantity("chip_erase_time");
    memory_.assign(static_cast<std::size_t>(size), 0xFF);
    if (params.has("image")) {
        const std::string image = params.text("image");
        const std::string bytes = read_input_file(image, "spi_flash image", static_cast<std::uint64_t>(size));
        std::copy(bytes.begin(), bytes.end(), memory_.begin());
    }
    cs_pin_ = add_pin("cs", TerminalRole::Input);
    sck_pin_ = add_pin("sck", TerminalRole::Input);
    mosi_pin_ = add_pin("mosi", TerminalRole::Input);
    // DO at byte level (periph/spi/Spi.hpp): an input here, so slaves sharing MISO do not fight.
    miso_pin_ = add_pin("miso", TerminalRole::Input);
    add_readout("programs", [this] { return static_cast<double>(programs_); });
    add_readout("erases", [this] { return static_cast<double>(erases_); });
}

void SpiFlash::start() {
    attach_spi_slave(*this, sck_pin_, mosi_pin_, miso_pin_, *this);
    selected_ = connected(cs_pin_) && !input_level(cs_pin_);
}

bool SpiFlash::busy() const { return clock().cycle() < busy_until_; }

std::uint8_t SpiFlash::status() const {
    std::uint8_t s = status_bits_;
    if (busy()) s |= kBusy;
    if (write_enabled_) s |= kWel;
    return s;
}

void SpiFlash::start_busy(double seconds) { busy_until_ = clock().cycle() + clock().cycles_from_seconds(seconds); }

void SpiFlash::on_input(std::size_t pin, bool level) {
    if (pin != cs_pin_) return;
    const bool selected = !level;
    if (selected == selected_) return;
    selected_ = selected;
    if (selected) {
        position_ = 0;
        page_.clear();
        ignore_ = false;
    } else if (position_ > 0 || command_ != 0) {
        end_command();
    }
}

// What the command byte and the bytes after it give back; the data bytes a
// read returns, the IDs, the status.
std::uint8_t SpiFlash::reply(std::uint8_t in) {
    const std::size_t n = position_++;
    if (n == 0) {
        command_ = in;
        // Busy or powered down, only Read Status (and, powered down, the release) is heard.
        const bool heard = command_ == kReadStatus || (powered_down_ ? command_ == kReleasePowerDown : !busy());
        if (!heard) {
            ignore_ = true;
            char text[120];
            std::snprintf(text, sizeof text, "instruction 0x%02X while %s", command_, powered_down_ ? "powered down" : "busy");
            report(kCommandWhileBusy, text);
        }
        return 0xFF;
    }
    if (ignore_) return 0xFF;
    const auto address_byte = [&](std::size_t i) {
        if (n >= 1 && n <= 3) address_ = (address_ << 8 | in) & 0xFFFFFF;
        return n < i;
    };
    switch (command_) {
        case kReadStatus: return status();
        case kWriteStatus:
            if (n == 1) status_bits_ = static_cast<std::uint8_t>(in & 0xBC);  // BP0, BP1, TB, SRP
            return 0xFF;
        case kRead:
        case kFastRead: {
            if (address_byte(4)) return 0xFF;
            const std::size_t first_data = command_ == kFastRead ? 5 : 4;  // fast read: a dummy byte
            if (n < first_data) return 0xFF;
            const std::uint8_t v = memory_[address_ % memory_.size()];
            address_ = (address_ + 1) % static_cast<std::uint32_t>(memory_.size());
            return v;
        }
        case kPageProgram:
            if (address_byte(4)) return 0xFF;
            page_.push_back(in);
            return 0xFF;
        case kSectorErase:
        case kBlock32Erase:
        case kBlock64Erase:
            address_byte(4);
            return 0xFF;
        case kManufacturerDevice:
            if (address_byte(4)) return 0xFF;
            // Address 0: manufacturer then device, alternating; address 1: device first.
            return ((n - 4 + (address_ & 1)) % 2 == 0) ? manufacturer_ : device_;
        case kJedecId: {
            const std::uint8_t id[3] = {manufacturer_, memory_type_, capacity_};
            return id[(n - 1) % 3];
        }
        case kReleasePowerDown:
            powered_down_ = false;
            return n >= 4 ? device_ : 0xFF;  // three dummy bytes, then the device ID
        case kUniqueId:
            return 0x00;  // four dummy bytes, then the 64-bit ID: zeros here
        default: return 0xFF;
    }
}

// Chip select rose: the commands that act at the end of their sequence.
void SpiFlash::end_command() {
    const std::uint8_t command = command_;
    command_ = 0;
    if (ignore_ || position_ == 0) return;
    const auto needs_wel = [&] {
        if (write_enabled_) return true;
        char text[120];
        std::snprintf(text, sizeof text, "instruction 0x%02X without Write Enable (0x06) first: ignored (datasheet §8.2)", command);
        report(kWriteNotEnabled, text);
        return false;
    };
    switch (command) {
        case kWriteEnable: write_enabled_ = true; break;
        case kWriteDisable: write_enabled_ = false; break;
        case kWriteStatus:
            if (!needs_wel()) break;
            write_enabled_ = false;
            break;
        case kPageProgram: {
            if (!needs_wel()) break;
            // Bytes past the page's end wrap to its start; programming only clears bits.
            const std::uint32_t page_start = address_ & ~static_cast<std::uint32_t>(kPageBytes - 1);
            for (std::size_t i = 0; i < page_.size(); ++i) {
                const std::uint32_t at = page_start + static_cast<std::uint32_t>(((address_ - page_start) + i) % kPageBytes);
                memory_[at % memory_.size()] &= page_[i];
            }
            ++programs_;
            write_enabled_ = false;
            start_busy(page_program_s_);
            break;
        }
        case kSectorErase:
        case kBlock32Erase:
        case kBlock64Erase:
        case kChipErase:
        case kChipErase2: {
            if (!needs_wel()) break;
            std::size_t size = memory_.size();
            double t = chip_erase_s_;
            if (command == kSectorErase) size = 4096, t = sector_erase_s_;
            if (command == kBlock32Erase) size = 32768, t = block_erase_s_;
            if (command == kBlock64Erase) size = 65536, t = block_erase_s_;
            const std::size_t start = size == memory_.size() ? 0 : (address_ % memory_.size()) & ~(size - 1);
            std::fill(memory_.begin() + static_cast<std::ptrdiff_t>(start),
                      memory_.begin() + static_cast<std::ptrdiff_t>(std::min(memory_.size(), start + size)), 0xFF);
            ++erases_;
            write_enabled_ = false;
            start_busy(t);
            break;
        }
        case kPowerDown: powered_down_ = true; break;
        case kReadStatus: case kRead: case kFastRead: case kManufacturerDevice: case kJedecId:
        case kReleasePowerDown: case kUniqueId: break;
        default: {
            char text[80];
            std::snprintf(text, sizeof text, "instruction 0x%02X (datasheet §8.2 lists it nowhere)", command);
            report(kUnknownCommand, text);
        }
    }
}

std::optional<std::uint8_t> SpiFlash::exchange(const SpiTransfer& transfer) {
    if (!selected_) return std::nullopt;
    // Modes 0 and 3, MSB first (datasheet §7.1); its 104 MHz is beyond any AVR's clock.
    if ((transfer.mode() != 0 && transfer.mode() != 3) || transfer.lsb_first) {
        if (!mode_reported_) {
            mode_reported_ = true;
            report(kSpiModeMismatch, spi_mode_problem(transfer, {transfer.mode() == 1 ? 0 : 3, false, 0, "W25X20CL datasheet §7.1: SPI mode 0 or 3, MSB first"}));
        }
    }
    return reply(transfer.mosi);
}

std::string SpiFlash::summary() {
    char text[160];
    std::snprintf(text, sizeof text, "flash      %s: %zu KB, JEDEC %02X %02X %02X, %llu programs, %llu erases%s", name().c_str(),
                  memory_.size() / 1024, manufacturer_, memory_type_, capacity_, static_cast<unsigned long long>(programs_),
                  static_cast<unsigned long long>(erases_), busy() ? ", busy" : "");
    return text;
}

void SpiFlash::on_bus_contention(const std::string& others, Cycle) {
    if (contention_reported_) return;
    contention_reported_ = true;
    report(kSpiBusContention, spi_contention_detail(others));
}

}  // namespace avrbench
