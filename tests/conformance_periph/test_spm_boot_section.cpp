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
//  - a watchdog reset the boot loader causes to leave is not a finding.
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "core/ElfImage.hpp"
#include "core/Errors.hpp"
#include "core/Mcu.hpp"
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
};

const SpmPart kUno{"ATmega328P", "spm_app", "spm_boot_loader", {0xFF, 0xDE, 0xFD}, 0x7E00, 128};
const SpmPart kMega{"ATmega2560", "spm_app_m2560", "spm_boot_loader_m2560", {0xFF, 0xD8, 0xFD}, 0x3E000, 256};

std::string hex_of(const char* name) {
    std::string path = test::firmware(name);
    return path.replace(path.size() - 4, 4, ".hex");
}

Mcu make(const SpmPart& part) {
    McuOptions options;
    options.fuses = part.fuses;
    options.bootloader_hex = hex_of(part.boot);
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
    mcu.reset_external();
    ASSERT_TRUE(run_until_done(mcu, 2));
    EXPECT_EQ(mcu.read_ram_u8("reset_cause"), 0x08) << "MCUSR.WDRF (bit 3) as the boot loader saw it";
    EXPECT_EQ(mcu.read_ram_u16("boot_page_pattern_bytes"), part.page_bytes)
        << "SPM from the boot section programs the page";
    EXPECT_EQ(mcu.resets(), 2u) << "the external reset and the boot loader's watchdog reset";
    EXPECT_TRUE(mcu.findings().empty()) << mcu.findings().front().describe();
    EXPECT_TRUE(mcu.elf_matches_flash()) << "the pages programmed lie outside the application's image";
}

std::string spm_part_name(const ::testing::TestParamInfo<const SpmPart*>& param_info) { return param_info.param->name; }

INSTANTIATE_TEST_SUITE_P(Parts, SpmBootSection, ::testing::Values(&kUno, &kMega), spm_part_name);

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
