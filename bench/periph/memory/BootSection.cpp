#include "periph/memory/BootSection.hpp"

#include <array>

namespace avrbench {

namespace {

struct BootTable {
    std::string_view mcu;
    std::uint32_t flash_bytes;
    int fuse_index;                // which fuse byte holds BOOTSZ1..0 (bits 2..1) and BOOTRST (bit 0)
    std::uint32_t smallest_words;  // boot size for BOOTSZ = 11; each step down doubles it
};

// Each datasheet's "Boot Size Configuration" table (Boot Loader Support
// chapter): BOOTSZ = 11 selects the smallest boot section, 10, 01 and 00
// twice, four and eight times that. Smallest: 128 words on the ATmega8,
// 16, 88 and 168; 256 on the ATmega32 and 328/P; 512 on the ATmega644/P,
// 1280/1281, 1284/P and 2560/2561. BOOTSZ and BOOTRST are bits 2..0 of the
// high fuse, except on the 88/168, where they are in the extended fuse.
// Check: Arduino's boards.txt pairs the UNO's 512-byte optiboot with high
// fuse 0xDE (BOOTSZ = 11 -> 256 words at 0x7E00) and the Mega 2560's 8 KB
// stk500v2 boot loader with 0xD8 (BOOTSZ = 00 -> 4096 words at 0x3E000).
constexpr std::array kTables{
    BootTable{"atmega8", 8 * 1024, 1, 128},          BootTable{"atmega16", 16 * 1024, 1, 128},
    BootTable{"atmega32", 32 * 1024, 1, 256},        BootTable{"atmega88", 8 * 1024, 2, 128},
    BootTable{"atmega88p", 8 * 1024, 2, 128},        BootTable{"atmega168", 16 * 1024, 2, 128},
    BootTable{"atmega168p", 16 * 1024, 2, 128},      BootTable{"atmega328", 32 * 1024, 1, 256},
    BootTable{"atmega328p", 32 * 1024, 1, 256},      BootTable{"atmega644", 64 * 1024, 1, 512},
    BootTable{"atmega644p", 64 * 1024, 1, 512},      BootTable{"atmega1280", 128 * 1024, 1, 512},
    BootTable{"atmega1281", 128 * 1024, 1, 512},     BootTable{"atmega1284", 128 * 1024, 1, 512},
    BootTable{"atmega1284p", 128 * 1024, 1, 512},    BootTable{"atmega2560", 256 * 1024, 1, 512},
    BootTable{"atmega2561", 256 * 1024, 1, 512},
};

}  // namespace

std::optional<BootSection> boot_section(std::string_view mcu_type, const std::uint8_t fuses[3]) {
    for (const BootTable& t : kTables) {
        if (t.mcu != mcu_type) continue;
        const std::uint8_t fuse = fuses[t.fuse_index];
        const unsigned bootsz = (fuse >> 1) & 0x3;  // 11 = smallest
        BootSection s;
        s.size_bytes = t.smallest_words * 2u << (3u - bootsz);
        s.start_bytes = t.flash_bytes - s.size_bytes;
        s.reset_into_boot = (fuse & 0x1) == 0;  // a fuse bit is programmed when 0
        return s;
    }
    return std::nullopt;
}

}  // namespace avrbench
