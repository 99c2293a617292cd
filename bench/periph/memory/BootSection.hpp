// The boot loader section of a megaAVR: where it starts and whether the
// reset vector is moved there, from the BOOTSZ and BOOTRST fuse bits
// ("Boot Loader Support - Read-While-Write Self-Programming" chapter of each
// datasheet). The boot section is the top of flash; the rest is the
// application section. SPM executes only from the boot section.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

namespace avrbench {

struct BootSection {
    std::uint32_t start_bytes = 0;  // first byte address of the boot section
    std::uint32_t size_bytes = 0;
    bool reset_into_boot = false;  // BOOTRST programmed (0): the reset vector is start_bytes
};

// `fuses` are low, high, extended (simavr's avr_t::fuse order). nullopt for
// an MCU the bench has no boot-size table for (see BootSection.cpp).
std::optional<BootSection> boot_section(std::string_view mcu_type, const std::uint8_t fuses[3]);

}  // namespace avrbench
