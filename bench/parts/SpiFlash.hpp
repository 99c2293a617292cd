// A serial NOR flash on the SPI bus: the Winbond W25X20CL (2 Mbit, 4 KB
// sectors) that the Einsy RAMBo carries as Prusa's XFLASH, and W25X/W25Q
// family parts of other sizes. Instructions: write enable/disable, read and
// write status, read, fast read, page program (256-byte pages, 1 -> 0 only),
// 4 KB sector, 32 KB and 64 KB block and chip erase, power-down and release,
// manufacturer/device ID (0x90), JEDEC ID (0x9F), unique ID (0x4B). Program
// and erase keep BUSY set for their time; what the firmware does wrong (a
// program without write enable, a command while busy or powered down, an
// unknown instruction) is a finding. The contents start erased (0xFF) or as
// `image` holds them; the file itself is never written.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/SpiBus.hpp"

namespace avrbench {

class SpiFlash final : public Part, public SpiSlave {
public:
    static const FindingKind kWriteNotEnabled;   // flash-write-not-enabled
    static const FindingKind kCommandWhileBusy;  // flash-command-while-busy
    static const FindingKind kUnknownCommand;    // flash-unknown-command
    static std::vector<ParamSpec> param_specs();

    SpiFlash(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "spi_flash"; }
    void start() override;
    std::string summary() override;

    const std::vector<std::uint8_t>& contents() const { return memory_; }
    std::uint8_t status() const;  // the status register as a read shows it now
    bool busy() const;
    std::uint64_t programs() const { return programs_; }
    std::uint64_t erases() const { return erases_; }

    std::optional<std::uint8_t> exchange(const SpiTransfer& transfer) override;
    const std::string& spi_name() const override { return name(); }
    void on_bus_contention(const std::string& others, Cycle cycle) override;

private:
    void on_input(std::size_t pin, bool level) override;
    void end_command();
    std::uint8_t reply(std::uint8_t in);
    void start_busy(double seconds);

    std::size_t cs_pin_, sck_pin_, mosi_pin_, miso_pin_;
    std::uint8_t manufacturer_, device_, memory_type_, capacity_;
    double page_program_s_, sector_erase_s_, block_erase_s_, chip_erase_s_;
    std::vector<std::uint8_t> memory_;

    bool selected_ = false;
    bool write_enabled_ = false;  // WEL
    bool powered_down_ = false;
    std::uint8_t status_bits_ = 0;  // BP0, BP1, TB, SRP as written
    Cycle busy_until_ = 0;
    // The transaction since chip select fell.
    std::uint8_t command_ = 0;
    std::size_t position_ = 0;  // bytes after the command byte
    std::uint32_t address_ = 0;
    std::vector<std::uint8_t> page_;  // page program data
    bool ignore_ = false;           // a refused command: the rest of it too
    std::uint64_t programs_ = 0, erases_ = 0;
    bool contention_reported_ = false;
    bool mode_reported_ = false;
};

}  // namespace avrbench
