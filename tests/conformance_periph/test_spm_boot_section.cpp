// Boot loader support (ATmega328P and ATmega2560 datasheets, "Boot Loader
// Support - Read-While-Write Self-Programming"), with the conformance pair in
// firmware/conformance/peripherals/spm_boot_section: a boot loader of ours
// (loaded from its Intel HEX as a board's boot loader is) and an application.
//
//  - BOOTRST programmed: every reset starts at the boot section (0x7E00 with
//    high fuse 0xDE on the 328P, 0x3E000 with 0xD8 on the 2560: BOOTSZ
//    tables), which then jumps to 0;
//  - SPM from the boot section programs a page; "it can only be executed
//    from the Boot Loader Flash section": the application's SPM leaves its
//    page erased. (simavr 1.6 programs the page from anywhere.)
//  - Boot lock bits ("Boot Lock Bit0/Bit1 Protection Modes"): BLB01 = 0
//    (bit 2) forbids SPM writes to the application section, BLB11 = 0 (bit 4)
//    to the boot section; SPM with BLBSET programs them from R0. Lock bytes:
//    none given = erased 0xFF; 0x0F as the Arduino IDE burns (BLB1 mode 3);
//    0x3B (BLB0 mode 2). (simavr 1.6 ignores all of them.)
//  - a watchdog reset the boot loader causes to leave is not a finding.
#include <gtest/gtest.h>

#include <array>
#include <optional>
#include <string>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

struct SpmPart {
    const char* name;
    const char* app;
    const char* boot;
    std::array<std::uint8_t, 3> fuses;  // Arduino boards.txt: UNO / Mega 2560
    std::uint32_t boot_start_bytes;     // from BOOTSZ, see above
    unsigned page_bytes;                // SPM_PAGESIZE: 64 words (328P), 128 words (2560)
    std::optional<std::uint8_t> lock_bits;
    bool application_section_writable;  // BLB01 (bit 2) unprogrammed
    bool boot_section_writable;         // BLB11 (bit 4) unprogrammed, before the boot loader programs it
};

const SpmPart kUno{"ATmega328P", "spm_app", "spm_boot_loader", {0xFF, 0xDE, 0xFD}, 0x7E00, 128, {}, true, true};
const SpmPart kMega{"ATmega2560", "spm_app_m2560", "spm_boot_loader_m2560", {0xFF, 0xD8, 0xFD}, 0x3E000, 256, {}, true, true};
const SpmPart kUnoArduinoLock{"ATmega328P_lock0x0F", "spm_app",  "spm_boot_loader", {0xFF, 0xDE, 0xFD}, 0x7E00,
                              128,                   0x0F,       true,              false};
const SpmPart kMegaArduinoLock{"ATmega2560_lock0x0F", "spm_app_m2560", "spm_boot_loader_m2560", {0xFF, 0xD8, 0xFD}, 0x3E000,
                               256,                   0x0F,            true,                    false};
const SpmPart kUnoApplicationLocked{"ATmega328P_lock0x3B", "spm_app", "spm_boot_loader", {0xFF, 0xDE, 0xFD}, 0x7E00,
                                    128,                   0x3B,      false,             true};

std::string hex_of(const char* name) {
    std::string path = test::firmware(name);
    return path.replace(path.size() - 4, 4, ".hex");
}

Mcu make(const SpmPart& part) {
    McuOptions options;
    options.fuses = part.fuses;
    options.bootloader_hex = hex_of(part.boot);
    options.lock_bits = part.lock_bits;
    return Mcu(ElfImage::load(test::firmware(part.app)), options);
}

// Until the application's `start`-th run has set `done` (RAM survives a reset).
bool run_until_done(Mcu& mcu, unsigned start) {
    const Cycle end = mcu.cycle() + 16'000'000;  // 1 s at 16 MHz; the program takes < 50 ms
    const auto finished = [&] { return mcu.application_starts() == start && mcu.read_ram_u8("done") == 1; };
    while (!finished() && mcu.cycle() < end && !mcu.halted()) mcu.run_for(1'000);
    return finished();
}

class SpmBootSection : public ::testing::TestWithParam<const SpmPart*> {};

TEST_P(SpmBootSection, ResetStartsInTheBootSectionAndOnlyItsSpmProgramsFlash) {
    const SpmPart& part = *GetParam();
    Mcu mcu = make(part);
    ASSERT_TRUE(mcu.boot().has_value());
    EXPECT_EQ(mcu.boot()->start_bytes, part.boot_start_bytes);
    EXPECT_EQ(mcu.pc_bytes(), part.boot_start_bytes) << "BOOTRST is programmed: the reset vector is the boot section";

    // Power-on: no EXTRF, so the boot loader jumps to the application.
    ASSERT_TRUE(run_until_done(mcu, 1));
    EXPECT_EQ(mcu.read_ram_u16("boot_page_pattern_bytes"), 0u) << "nothing programmed the page yet";
    EXPECT_EQ(mcu.read_ram_u16("app_page_erased_bytes"), part.page_bytes)
        << "an SPM executed from the application section must not program flash";

    // External reset: the boot loader programs its page, leaves through a
    // 16 ms watchdog reset (WDRF), and starts the application again.
    // RAM survives the reset: clear `done` so that only the next run sets it
    // (the application's start-up code zeroes it too, a few hundred cycles in).
    mcu.poke(*mcu.elf().symbol_address("done") - 0x800000, 0);
    mcu.reset_external();
    ASSERT_TRUE(run_until_done(mcu, 2));
    EXPECT_EQ(mcu.read_ram_u8("reset_cause"), 0x08) << "MCUSR.WDRF (bit 3) as the boot loader saw it";
    EXPECT_EQ(mcu.read_ram_u16("boot_page_pattern_bytes"), part.application_section_writable ? part.page_bytes : 0u)
        << "SPM from the boot section programs an application page unless BLB01 is programmed";
    EXPECT_EQ(mcu.read_ram_u16("boot_self_pattern_bytes"), part.boot_section_writable ? part.page_bytes : 0u)
        << "SPM writes to the boot section unless BLB11 is programmed";
    EXPECT_EQ(mcu.read_ram_u16("boot_locked_pattern_bytes"), 0u) << "the boot loader programmed BLB11 first";
    EXPECT_EQ(mcu.lockbits() & 0x10, 0) << "BLB11 programmed by SPM with BLBSET";
    EXPECT_EQ(mcu.resets(), 2u) << "the external reset and the boot loader's watchdog reset";
    EXPECT_TRUE(mcu.findings().empty()) << mcu.findings().front().describe();
    EXPECT_TRUE(mcu.elf_matches_flash()) << "the pages programmed lie outside the application's image";
    EXPECT_EQ(mcu.read_ram_u16("app_page_erased_bytes"), part.page_bytes);
}

std::string spm_part_name(const ::testing::TestParamInfo<const SpmPart*>& param_info) { return param_info.param->name; }

INSTANTIATE_TEST_SUITE_P(Parts, SpmBootSection, ::testing::Values(&kUno, &kMega, &kUnoArduinoLock, &kMegaArduinoLock,
                                                                   &kUnoApplicationLocked),
                         spm_part_name);

TEST(BootLoaderErrors, NamesTheFileAndTheProblem) {
    McuOptions options;
    options.bootloader_hex = hex_of("spm_boot_loader");
    try {
        Mcu mcu(ElfImage::load(test::firmware("spm_app")), options);
        FAIL() << "a boot loader without fuses was accepted";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("needs the fuses"), std::string::npos) << e.what();
    }
    // High fuse 0xDC: BOOTSZ = 10, 512 words at 0x7C00; the image at 0x7E00
    // fits inside. 0xD8's 2048 words start at 0x7000: still inside. The
    // 2560's boot loader on a 328P lies past the 32 KB flash.
    options.fuses = std::array<std::uint8_t, 3>{0xFF, 0xDE, 0xFD};
    options.bootloader_hex = hex_of("spm_boot_loader_m2560");
    try {
        Mcu mcu(ElfImage::load(test::firmware("spm_app")), options);
        FAIL() << "a boot loader outside the flash was accepted";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("outside the boot section 0x07E00..0x07FFF"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avrbench
