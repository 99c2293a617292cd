// A firmware ELF, read by the bench itself (libelf, every offset and size
// bounds-checked) and handed to simavr as a firmware structure built from
// validated data: simavr's own elf_read_firmware() trusts its input and
// copies .mmcu tags into fixed buffers, and it places .data right after
// .text instead of at its load address.
//
// The flash image is built from the ELF's loadable segments at their load
// (physical) addresses, as avr-objcopy does for a .hex: .data lands where the
// start-up code copies it from (__data_load_start) whatever sections the
// linker put before it. Also: symbols for the oracles (end of .bss,
// __bad_interrupt) and `function+offset` names for PCs.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct elf_firmware_t;  // simavr's parsed firmware (sim_elf.h)
struct Elf;             // libelf's handle

namespace avrbench {

class ElfImage {
public:
    // Throws BadInput with one line naming the file and the problem when it is
    // missing, not an ELF, not an AVR executable, or malformed (sections,
    // segments, symbols or .mmcu tags out of bounds or inconsistent).
    static ElfImage load(const std::string& path);

    const std::string& path() const { return path_; }
    // From simavr's `.mmcu` section (avr_mcu_section.h); empty / 0 if absent.
    const std::string& embedded_mcu() const { return embedded_mcu_; }
    std::uint32_t embedded_frequency_hz() const { return embedded_frequency_hz_; }

    std::optional<std::uint32_t> symbol_address(const std::string& name) const;
    // A data object's size in bytes as the symbol table gives it (st_size of
    // an STT_OBJECT), nothing for other symbols.
    std::optional<std::uint32_t> object_size(const std::string& name) const {
        const auto it = object_sizes_.find(name);
        return it == object_sizes_.end() ? std::nullopt : std::optional<std::uint32_t>(it->second);
    }

    // "name+0x12" for a flash byte address, or "0x1234" when no symbol covers it.
    std::string describe_flash_address(std::uint32_t pc_bytes) const;

    // First byte past the end of .data/.bss/.noinit in data space (SRAM address),
    // i.e. the lowest address the stack may reach; 0 if unknown.
    std::uint32_t ram_end_of_static_data() const { return ram_static_end_; }

    // First flash byte past .text: where code ends (the .mmcu and .data load
    // images that may follow are not code).
    std::uint32_t text_end_bytes() const { return text_end_; }

    // The firmware for avr_load_firmware(): pointers into this image's
    // buffers (valid while it lives), no VCD trace, no symbols.
    elf_firmware_t simavr_firmware() const;

private:
    static void load_segments(Elf* elf, int fd, std::uint64_t file_size, const std::string& path, ElfImage& image);
    static void parse_mmcu(const std::vector<std::uint8_t>& section, const std::string& path, ElfImage& image);

    std::string path_;
    std::uint32_t flash_base_ = 0;
    std::shared_ptr<std::vector<std::uint8_t>> flash_;   // shared: images are copied cheaply
    std::shared_ptr<std::vector<std::uint8_t>> eeprom_;
    std::vector<std::uint8_t> fuses_;
    std::optional<std::uint8_t> lock_bits_;
    std::uint32_t text_end_ = 0;
    std::uint32_t vcc_mv_ = 0, avcc_mv_ = 0, aref_mv_ = 0;
    struct ExternalPull {
        char port;
        std::uint8_t mask, value;
    };
    std::vector<ExternalPull> external_pulls_;
    std::uint16_t console_register_ = 0;
    std::string embedded_mcu_;
    std::uint32_t embedded_frequency_hz_ = 0;
    std::map<std::string, std::uint32_t> symbols_;         // all named symbols
    std::map<std::string, std::uint32_t> object_sizes_;    // data objects' sizes
    std::map<std::uint32_t, std::string> flash_functions_;  // code symbols by byte address
    std::uint32_t ram_static_end_ = 0;
};

}  // namespace avrbench
