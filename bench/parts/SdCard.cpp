#include "parts/SdCard.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "mcu/Mcu.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(SdCard, "sd_card");

const FindingKind SdCard::kCommandCrc = FindingKind::declare(
    "sd-command-crc", "an SD card command whose CRC7 was wrong where the card checks it (CMD0, CMD8, or all after CMD59)",
    Severity::Warning);
const FindingKind SdCard::kIllegalCommand = FindingKind::declare(
    "sd-illegal-command", "an SD card command that SPI mode does not have (R1 illegal command)", Severity::Warning);

namespace {

constexpr std::size_t kBlock = 512;
// R1 bits (§7.3.2.1): in idle state, illegal command, command CRC error,
// address error, parameter error.
constexpr std::uint8_t kIdle = 0x01, kIllegal = 0x04, kCrcError = 0x08, kAddressError = 0x20;
// Data tokens (§7.3.3): start block (single and multiple read, single
// write), start block of a multiple write, stop transmission; data response
// (§7.3.3.1): accepted, CRC error.
constexpr std::uint8_t kStartBlock = 0xFE, kStartMultiWrite = 0xFC, kStopTran = 0xFD;
constexpr std::uint8_t kDataAccepted = 0x05, kDataCrcError = 0x0B;

// CRC7 of commands and registers (§4.5: G(x) = x^7 + x^3 + 1).
std::uint8_t crc7(const std::uint8_t* data, std::size_t n) {
    std::uint8_t crc = 0;
    for (std::size_t i = 0; i < n; ++i) {
        std::uint8_t d = data[i];
        for (int b = 0; b < 8; ++b) {
            crc = static_cast<std::uint8_t>(crc << 1);
            if (((d & 0x80) != 0) != ((crc & 0x80) != 0)) crc ^= 0x09;
            d = static_cast<std::uint8_t>(d << 1);
        }
        crc &= 0x7F;
    }
    return crc;
}

// CRC16 of data blocks (§4.5: CRC-CCITT, G(x) = x^16 + x^12 + x^5 + 1, from 0).
std::uint16_t crc16(const std::uint8_t* data, std::size_t n) {
    std::uint16_t crc = 0;
    for (std::size_t i = 0; i < n; ++i) {
        crc = static_cast<std::uint16_t>(crc ^ (data[i] << 8));
        for (int b = 0; b < 8; ++b) crc = static_cast<std::uint16_t>((crc & 0x8000) != 0 ? (crc << 1) ^ 0x1021 : crc << 1);
    }
    return crc;
}

// Sets bits [hi:lo] of a 128-bit register (bit 127 the first byte's MSB).
void set_bits(std::vector<std::uint8_t>& reg, int hi, int lo, std::uint32_t value) {
    for (int b = lo; b <= hi; ++b) {
        const bool one = ((value >> (b - lo)) & 1u) != 0;
        const std::size_t byte = static_cast<std::size_t>((127 - b) / 8);
        const auto mask = static_cast<std::uint8_t>(1u << (b % 8));
        reg[byte] = one ? static_cast<std::uint8_t>(reg[byte] | mask) : static_cast<std::uint8_t>(reg[byte] & ~mask);
    }
}

void finish_register(std::vector<std::uint8_t>& reg) { reg[15] = static_cast<std::uint8_t>(crc7(reg.data(), 15) << 1 | 1); }

// A folder's files by name (so the card is the same wherever the folder is
// checked out), each read as an input file.
std::vector<FatFile> folder_files(const std::string& folder, const std::string& part) {
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) throw part_error(part, "folder " + folder + ": no such folder");
    std::vector<std::filesystem::path> paths;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
        if (entry.is_directory()) throw part_error(part, "folder " + folder + ": '" + entry.path().filename().string() +
                                                             "' is a folder (the card gets only the top level's files)");
        paths.push_back(entry.path());
    }
    if (ec) throw part_error(part, "folder " + folder + ": " + ec.message());
    std::sort(paths.begin(), paths.end());
    std::vector<FatFile> files;
    for (const auto& p : paths) files.push_back({p.filename().string(), read_input_file(p.string(), "sd_card file", 32u << 20)});
    return files;
}

}  // namespace

std::vector<ParamSpec> SdCard::param_specs() {
    using PT = ParamType;
    using D = Dimension;
    return {
        {.name = "image", .type = PT::Path,
         .help = "a disk image (a multiple of 512 bytes, at most 1 GiB), read once; written only with write_back: yes"},
        {.name = "folder", .type = PT::Path,
         .help = "instead of an image: a folder whose files (8.3 names, no subfolders) go on a 32 MiB FAT16 card"},
        {.name = "write_back", .type = PT::Choice, .default_value = "no", .choices = {"no", "yes"},
         .help = "yes: each block the firmware writes goes to `image` too (the file changes); no: the card's copy only"},
        {.name = "size", .type = PT::Integer, .default_value = "8388608", .source = "assumed: an 8 MiB card when no image is given",
         .help = "bytes without an image (a multiple of 512 KiB)", .min = 524288, .max = 1073741824},
        {.name = "card", .type = PT::Choice, .default_value = "sdhc", .choices = {"sdhc", "sdsc"},
         .help = "SDHC (block addresses, CSD 2.0, OCR CCS 1) or SDSC (byte addresses, CSD 1.0)"},
        {.name = "inserted", .type = PT::Choice, .default_value = "yes", .choices = {"yes", "no"},
         .help = "no: an empty slot (nothing answers, detect open)"},
        {.name = "init_time", .type = PT::Quantity, .dimension = D::Time, .default_value = "10ms",
         .source = "assumed: the spec allows up to 1 s (§4.2.3); cards take tens of ms",
         .help = "ACMD41 answers 'idle' until this long after the first one", .min = 0, .max = 1},
        {.name = "write_latency", .type = PT::Quantity, .dimension = D::Time, .default_value = "1ms",
         .source = "assumed: a typical block write (the spec's limit is 250 ms, §4.6.2.2)",
         .help = "busy (MISO low) after each block written", .min = 0, .max = 1},
    };
}

SdCard::SdCard(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    inserted_ = params.text("inserted") == "yes";
    sdhc_ = params.text("card") == "sdhc";
    init_time_s_ = params.quantity("init_time");
    write_latency_s_ = params.quantity("write_latency");
    if (params.has("image") && params.has("folder")) throw part_error(this->name(), "give an image or a folder, not both");
    if (params.has("image")) {
        const std::string bytes = read_input_file(params.text("image"), "sd_card image", 1u << 30);
        if (bytes.empty() || bytes.size() % kBlock != 0) {
            throw part_error(this->name(), "image " + params.text("image") + " is " + std::to_string(bytes.size()) +
                                               " bytes, not a whole number of 512-byte blocks");
        }
        memory_.assign(bytes.begin(), bytes.end());
        if (params.text("write_back") == "yes") write_back_path_ = params.text("image");
    } else if (params.has("folder")) {
        if (params.text("write_back") == "yes") throw part_error(this->name(), "write_back needs an image (a folder's card is made in memory)");
        memory_ = make_fat16_volume(folder_files(params.text("folder"), this->name()), "part '" + this->name() + "': folder " + params.text("folder"));
    } else {
        if (params.text("write_back") == "yes") throw part_error(this->name(), "write_back needs an image");
        const long long size = params.integer("size");
        if (size % (512 * 1024) != 0) throw part_error(this->name(), "size must be a multiple of 512 KiB");
        memory_.assign(static_cast<std::size_t>(size), 0);
    }
    cs_pin_ = add_pin("cs", TerminalRole::Input);
    sck_pin_ = add_pin("sck", TerminalRole::Input);
    mosi_pin_ = add_pin("mosi", TerminalRole::Input);
    // DO at byte level (periph/spi/Spi.hpp): an input here, so slaves sharing MISO do not fight.
    miso_pin_ = add_pin("miso", TerminalRole::Input);
    detect_pin_ = add_pin("detect", TerminalRole::Output);
    add_readout("blocks_read", [this] { return static_cast<double>(blocks_read_); });
    add_readout("blocks_written", [this] { return static_cast<double>(blocks_written_); });
}

void SdCard::start() {
    attach_spi_slave(*this, sck_pin_, mosi_pin_, miso_pin_, *this);
    selected_ = connected(cs_pin_) && !input_level(cs_pin_);
    // The slot's switch closes to GND with a card in; open, the MCU's pull-up decides.
    if (inserted_) {
        drive_output(detect_pin_, false);
    } else {
        release_output(detect_pin_);
    }
}

void SdCard::on_input(std::size_t pin, bool level) {
    if (pin == cs_pin_) selected_ = !level;
}

std::optional<std::vector<FatFile>> SdCard::stored_files() const {
    if (!inserted_) return std::nullopt;
    return read_fat_root_files(memory_);
}

void SdCard::write_back(std::uint64_t offset, const std::uint8_t* block) const {
    std::fstream file(write_back_path_, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(offset));
    file.write(reinterpret_cast<const char*>(block), kBlock);
    file.flush();
    if (!file) throw part_error(name(), "write_back: cannot write block " + std::to_string(offset / kBlock) + " of " + write_back_path_);
}

std::uint8_t SdCard::r1() const { return idle_ ? kIdle : 0; }

std::optional<std::uint8_t> SdCard::exchange(const SpiTransfer& transfer) {
    if (!inserted_ || !selected_) return std::nullopt;
    return byte(transfer.mosi);
}

void SdCard::queue_block(std::uint64_t offset) {
    std::vector<std::uint8_t> b = {0xFF, kStartBlock};  // one byte of access time, then the token
    b.insert(b.end(), memory_.begin() + static_cast<std::ptrdiff_t>(offset), memory_.begin() + static_cast<std::ptrdiff_t>(offset + kBlock));
    const std::uint16_t crc = crc16(memory_.data() + offset, kBlock);
    b.push_back(static_cast<std::uint8_t>(crc >> 8));
    b.push_back(static_cast<std::uint8_t>(crc));
    out_.insert(out_.end(), b.begin(), b.end());
    ++blocks_read_;
}

// The next queued byte for MISO; a multiple-block read queues its next block.
std::uint8_t SdCard::pop_out() {
    const std::uint8_t v = out_[out_pos_++];
    if (out_pos_ == out_.size()) {
        out_.clear();
        out_pos_ = 0;
        if (reading_multiple_) {
            if (next_read_offset_ + kBlock <= memory_.size()) {
                queue_block(next_read_offset_);
                next_read_offset_ += kBlock;
            } else {
                reading_multiple_ = false;
            }
        }
    }
    return v;
}

std::uint8_t SdCard::byte(std::uint8_t in) {
    const Cycle now = clock().cycle();
    const bool out_pending = out_pos_ < out_.size();
    // Command bytes: 01 then the index, 4 argument bytes, CRC7 and the end
    // bit; CMD12 may come while a multiple-block read streams.
    if (!writing_ && (cmd_len_ > 0 || ((in & 0xC0) == 0x40 && (!out_pending || reading_multiple_)))) {
        cmd_[cmd_len_++] = in;
        if (cmd_len_ == 6) {
            cmd_len_ = 0;
            command(cmd_);
            return 0xFF;
        }
        return out_pending ? pop_out() : 0xFF;
    }
    // Responses, data blocks and data response tokens, in order.
    if (out_pending) return pop_out();
    if (now < busy_until_) return 0x00;  // programming: MISO held low (§7.2.4)
    if (!writing_) return 0xFF;
    // A block being written: its token, 512 bytes and CRC16.
    if (write_buffer_.empty() && in != kStartBlock && in != kStartMultiWrite) {
        if (writing_multiple_ && in == kStopTran) {
            writing_ = writing_multiple_ = false;
            busy_until_ = now + clock().cycles_from_seconds(write_latency_s_);
        }
        return 0xFF;
    }
    write_buffer_.push_back(in);
    if (write_buffer_.size() < 1 + kBlock + 2) return 0xFF;
    const std::uint8_t* data = write_buffer_.data() + 1;
    const std::uint16_t sent = static_cast<std::uint16_t>(write_buffer_[1 + kBlock] << 8 | write_buffer_[2 + kBlock]);
    std::uint8_t response = kDataAccepted;
    if (crc_on_ && crc16(data, kBlock) != sent) {
        response = kDataCrcError;
    } else {
        std::copy(data, data + kBlock, memory_.begin() + static_cast<std::ptrdiff_t>(write_offset_));
        if (!write_back_path_.empty()) write_back(write_offset_, data);
        ++blocks_written_;
        write_offset_ += kBlock;
        if (write_offset_ + kBlock > memory_.size()) writing_multiple_ = false;
    }
    write_buffer_.clear();
    if (!writing_multiple_) writing_ = false;
    // The data response on the next byte, then busy while the block is programmed.
    respond({response});
    busy_until_ = now + clock().cycles_from_seconds(write_latency_s_);
    return 0xFF;
}

void SdCard::command(const std::array<std::uint8_t, 6>& c) {
    const unsigned index = c[0] & 0x3F;
    const std::uint32_t arg = static_cast<std::uint32_t>(c[1]) << 24 | c[2] << 16 | c[3] << 8 | c[4];
    const bool app = app_command_;
    app_command_ = false;
    // Before CMD0 the card is in SD mode and ignores the SPI bus.
    if (!spi_mode_ && index != 0) return;
    out_.clear();
    out_pos_ = 0;
    // CRC7: always checked on CMD0 and CMD8 (§7.2.2), on every command after CMD59 turns it on.
    const bool crc_checked = index == 0 || index == 8 || crc_on_;
    if (crc_checked && (c[5] >> 1) != crc7(c.data(), 5)) {
        char text[100];
        std::snprintf(text, sizeof text, "CMD%u with CRC7 0x%02X, the command's is 0x%02X", index, c[5] >> 1, crc7(c.data(), 5));
        report(kCommandCrc, text);
        respond({0xFF, static_cast<std::uint8_t>(r1() | kCrcError)});
        return;
    }
    const auto address_of = [&](std::uint32_t a) -> std::optional<std::uint64_t> {
        const std::uint64_t offset = sdhc_ ? static_cast<std::uint64_t>(a) * kBlock : a;
        if (offset % kBlock != 0 || offset + kBlock > memory_.size()) return std::nullopt;
        return offset;
    };
    const std::uint8_t ncr = 0xFF;  // one byte before every response (N_CR, §7.5.1)
    if (app && index == 41) {       // ACMD41 SD_SEND_OP_COND
        if (!init_started_) init_started_ = clock().cycle();
        if (static_cast<double>(clock().cycle() - *init_started_) / clock().frequency_hz() >= init_time_s_) idle_ = false;
        respond({ncr, r1()});
        return;
    }
    switch (index) {
        case 0:  // GO_IDLE_STATE: into SPI mode (CS low), idle
            spi_mode_ = true;
            idle_ = true;
            init_started_.reset();
            reading_multiple_ = writing_ = writing_multiple_ = false;
            respond({ncr, kIdle});
            return;
        case 1:  // SEND_OP_COND (thin cards, MMC): as ACMD41
            if (!init_started_) init_started_ = clock().cycle();
            if (static_cast<double>(clock().cycle() - *init_started_) / clock().frequency_hz() >= init_time_s_) idle_ = false;
            respond({ncr, r1()});
            return;
        case 8:  // SEND_IF_COND: R7 echoes the voltage and the check pattern
            respond({ncr, r1(), 0x00, 0x00, static_cast<std::uint8_t>((arg >> 8) & 0x0F), static_cast<std::uint8_t>(arg)});
            return;
        case 9:   // SEND_CSD
        case 10: {  // SEND_CID: R1, then the register as a data block (token, 16 bytes, CRC16)
            const auto reg = index == 9 ? csd() : cid();
            std::vector<std::uint8_t> b = {ncr, r1(), 0xFF, kStartBlock};
            b.insert(b.end(), reg.begin(), reg.end());
            const std::uint16_t crc = crc16(reg.data(), reg.size());
            b.push_back(static_cast<std::uint8_t>(crc >> 8));
            b.push_back(static_cast<std::uint8_t>(crc));
            respond(b);
            return;
        }
        case 12:  // STOP_TRANSMISSION: R1b after a stuff byte
            reading_multiple_ = false;
            respond({ncr, ncr, r1()});
            return;
        case 13:  // SEND_STATUS: R2
            respond({ncr, r1(), 0x00});
            return;
        case 16:  // SET_BLOCKLEN: 512 only (SDHC ignores it)
            respond({ncr, static_cast<std::uint8_t>(r1() | (arg != kBlock && !sdhc_ ? 0x40 : 0))});
            return;
        case 17:
        case 18: {  // READ_SINGLE_BLOCK, READ_MULTIPLE_BLOCK
            const auto offset = address_of(arg);
            if (!offset || idle_) {
                respond({ncr, static_cast<std::uint8_t>(r1() | (offset ? kIllegal : kAddressError))});
                return;
            }
            respond({ncr, r1()});
            queue_block(*offset);
            reading_multiple_ = index == 18;
            next_read_offset_ = *offset + kBlock;
            return;
        }
        case 24:
        case 25: {  // WRITE_BLOCK, WRITE_MULTIPLE_BLOCK
            const auto offset = address_of(arg);
            if (!offset || idle_) {
                respond({ncr, static_cast<std::uint8_t>(r1() | (offset ? kIllegal : kAddressError))});
                return;
            }
            respond({ncr, r1()});
            writing_ = true;
            writing_multiple_ = index == 25;
            write_offset_ = *offset;
            write_buffer_.clear();
            return;
        }
        case 55:  // APP_CMD: the next command is an application command
            app_command_ = true;
            respond({ncr, r1()});
            return;
        case 58: {  // READ_OCR: power-up done (bit 31), CCS (bit 30), 2.7-3.6 V (bits 23:15)
            std::uint32_t ocr = 0x00FF8000;
            if (!idle_) ocr |= 0x80000000u | (sdhc_ ? 0x40000000u : 0);
            respond({ncr, r1(), static_cast<std::uint8_t>(ocr >> 24), static_cast<std::uint8_t>(ocr >> 16),
                     static_cast<std::uint8_t>(ocr >> 8), static_cast<std::uint8_t>(ocr)});
            return;
        }
        case 59:  // CRC_ON_OFF
            crc_on_ = (arg & 1) != 0;
            respond({ncr, r1()});
            return;
        default: {
            char text[80];
            std::snprintf(text, sizeof text, "%sCMD%u (arg 0x%08X)", app ? "A" : "", index, arg);
            report(kIllegalCommand, text);
            respond({ncr, static_cast<std::uint8_t>(r1() | kIllegal)});
        }
    }
}

// CSD (§5.3): version 2.0 for SDHC (C_SIZE in 512 KiB units), 1.0 for SDSC
// (READ_BL_LEN 9, C_SIZE_MULT 7: C_SIZE in 256 KiB units).
std::vector<std::uint8_t> SdCard::csd() const {
    std::vector<std::uint8_t> r(16, 0);
    set_bits(r, 127, 126, sdhc_ ? 1 : 0);
    set_bits(r, 119, 112, 0x0E);   // TAAC 1.0 ms
    set_bits(r, 103, 96, 0x32);    // TRAN_SPEED 25 MHz
    set_bits(r, 95, 84, 0x5B5);    // CCC
    set_bits(r, 83, 80, 9);        // READ_BL_LEN 512
    set_bits(r, 46, 46, 1);        // ERASE_BLK_EN
    set_bits(r, 45, 39, 0x7F);     // SECTOR_SIZE
    set_bits(r, 28, 26, 2);        // R2W_FACTOR
    set_bits(r, 25, 22, 9);        // WRITE_BL_LEN 512
    if (sdhc_) {
        set_bits(r, 69, 48, static_cast<std::uint32_t>(memory_.size() / (512 * 1024) - 1));
    } else {
        set_bits(r, 79, 79, 1);    // READ_BL_PARTIAL
        set_bits(r, 73, 62, static_cast<std::uint32_t>(memory_.size() / (256 * 1024) - 1));
        set_bits(r, 49, 47, 7);    // C_SIZE_MULT
    }
    finish_register(r);
    return r;
}

// CID (§5.2): manufacturer 0, OEM "AB", product "BENCH", revision 1.0,
// serial 1, made December 2026.
std::vector<std::uint8_t> SdCard::cid() const {
    std::vector<std::uint8_t> r = {0x00, 'A', 'B', 'B', 'E', 'N', 'C', 'H', 0x10, 0, 0, 0, 1, 0x01, 0xAC, 0};
    finish_register(r);
    return r;
}

void SdCard::on_bus_contention(const std::string& others, Cycle) {
    if (contention_reported_) return;
    contention_reported_ = true;
    report(kSpiBusContention, spi_contention_detail(others));
}

std::string SdCard::summary() {
    char text[160];
    std::snprintf(text, sizeof text, "sd card    %s: %s%s, %zu KiB, %llu blocks read, %llu written", name().c_str(),
                  inserted_ ? "" : "no card in the slot; ", sdhc_ ? "SDHC" : "SDSC", memory_.size() / 1024,
                  static_cast<unsigned long long>(blocks_read_), static_cast<unsigned long long>(blocks_written_));
    return text;
}

}  // namespace avrbench
