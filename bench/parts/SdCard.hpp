// An SD card in SPI mode (SD Physical Layer Simplified Specification, Part 1,
// §7 "SPI Mode"): CMD0, CMD8, CMD55/ACMD41, CMD58, CMD9, CMD10, CMD12,
// CMD13, CMD16, CMD17, CMD18, CMD24, CMD25, CMD59; R1/R2/R3/R7 responses,
// data tokens, CRC7 on commands (always for CMD0 and CMD8, for all once CMD59
// turns it on) and CRC16 on data, busy after writes for `write_latency`.
// The contents come from `image` (a disk image: a FAT file system made with
// mkfs.vfat and mcopy, docs/BOARDS.md) or `folder` (its files on a FAT16
// volume the part makes) and stay in memory: the image is written only with
// `write_back: yes`, each block as the firmware writes it. Pin `detect` is the slot's card-detect switch (closed to GND
// with a card in).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/SpiBus.hpp"
#include "parts/StoredFiles.hpp"

namespace avrbench {

class SdCard final : public Part, public SpiSlave, public StoredFiles {
public:
    static const FindingKind kCommandCrc;     // sd-command-crc
    static const FindingKind kIllegalCommand;  // sd-illegal-command
    static std::vector<ParamSpec> param_specs();

    SdCard(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "sd_card"; }
    void start() override;
    std::string summary() override;

    const std::vector<std::uint8_t>& contents() const { return memory_; }
    bool high_capacity() const { return sdhc_; }
    std::uint64_t blocks_read() const { return blocks_read_; }
    std::uint64_t blocks_written() const { return blocks_written_; }

    std::optional<std::uint8_t> exchange(const SpiTransfer& transfer) override;
    std::optional<std::vector<FatFile>> stored_files() const override;
    const std::string& spi_name() const override { return name(); }
    void on_bus_contention(const std::string& others, Cycle cycle) override;

private:
    enum class Phase { Command, Response, ReadData, WriteWaitToken, WriteData, Busy };
    void on_input(std::size_t pin, bool level) override;
    std::uint8_t byte(std::uint8_t in);
    std::uint8_t pop_out();
    void command(const std::array<std::uint8_t, 6>& c);
    void respond(std::vector<std::uint8_t> bytes) { out_ = std::move(bytes); out_pos_ = 0; }
    void queue_block(std::uint64_t offset);
    std::uint8_t r1() const;
    void write_back(std::uint64_t offset, const std::uint8_t* block) const;
    std::vector<std::uint8_t> csd() const;
    std::vector<std::uint8_t> cid() const;

    std::size_t cs_pin_, sck_pin_, mosi_pin_, miso_pin_, detect_pin_;
    bool inserted_;
    bool sdhc_;
    double init_time_s_, write_latency_s_;
    std::vector<std::uint8_t> memory_;
    std::string write_back_path_;  // the image the firmware's writes go to as well; empty: none

    bool selected_ = false;
    bool idle_ = true;          // R1 bit 0: in the idle state until ACMD41 completes
    bool spi_mode_ = false;     // CMD0 with CS low puts the card in SPI mode
    bool app_command_ = false;  // the last command was CMD55
    bool crc_on_ = false;
    std::optional<Cycle> init_started_;
    std::array<std::uint8_t, 6> cmd_{};
    std::size_t cmd_len_ = 0;
    std::vector<std::uint8_t> out_;  // bytes queued for MISO
    std::size_t out_pos_ = 0;
    bool reading_multiple_ = false;
    std::uint64_t next_read_offset_ = 0;
    bool writing_ = false, writing_multiple_ = false;
    std::uint64_t write_offset_ = 0;
    std::vector<std::uint8_t> write_buffer_;
    Cycle busy_until_ = 0;
    std::uint64_t blocks_read_ = 0, blocks_written_ = 0;
    bool contention_reported_ = false;
};

}  // namespace avrbench
