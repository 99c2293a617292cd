// A firmware ELF, validated before simavr sees it, with the symbols the
// oracles need (end of .bss, __bad_interrupt) and a nearest-symbol lookup for
// reporting a PC as `function+offset`.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>

struct elf_firmware_t;  // simavr's parsed firmware (sim_elf.h)

namespace avrbench {

class ElfImage {
public:
    // Throws BadInput with one line naming the file when it is missing, not an
    // ELF, or not an AVR ELF (e_machine != EM_AVR).
    static ElfImage load(const std::string& path);

    const std::string& path() const { return path_; }
    // From simavr's `.mmcu` section (avr_mcu_section.h); empty / 0 if absent.
    const std::string& embedded_mcu() const { return embedded_mcu_; }
    std::uint32_t embedded_frequency_hz() const { return embedded_frequency_hz_; }

    std::optional<std::uint32_t> symbol_address(const std::string& name) const;

    // "name+0x12" for a flash byte address, or "0x1234" when no symbol covers it.
    std::string describe_flash_address(std::uint32_t pc_bytes) const;

    // First byte past the end of .data/.bss/.noinit in data space (SRAM address),
    // i.e. the lowest address the stack may reach; 0 if unknown.
    std::uint32_t ram_end_of_static_data() const { return ram_static_end_; }

    // simavr's own parse of the same file, ready for avr_load_firmware().
    elf_firmware_t& simavr_firmware() const { return *firmware_; }

private:
    std::string path_;
    std::shared_ptr<elf_firmware_t> firmware_;
    std::string embedded_mcu_;
    std::uint32_t embedded_frequency_hz_ = 0;
    std::map<std::string, std::uint32_t> symbols_;         // all named symbols
    std::map<std::uint32_t, std::string> flash_functions_;  // code symbols by byte address
    std::uint32_t ram_static_end_ = 0;
};

}  // namespace avrbench
