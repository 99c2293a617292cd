// The bench's ELF loader: .data from its load address whatever the linker
// put before it, and malformed files as one line with exit code 2.
#include <gtest/gtest.h>
#include <elf.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;

// firmware/data_init: sends its .data string "ok\n" and stores the sum of
// its .data table, 1+2+...+128 + 0x1000 = 0x10ff.
void expect_data_loaded(const std::string& firmware) {
    Mcu mcu(ElfImage::load(test::firmware(firmware)));
    Uart& uart = mcu.uart(0);
    mcu.run_until(32000);  // 2 ms: three 85 us frames are long done
    EXPECT_EQ(uart.transmitted_text(), "ok\n") << firmware;
    EXPECT_EQ(mcu.read_ram_u16("table_sum"), 0x10ff) << firmware;
}

TEST(ElfLoading, DataLoadsFromItsLoadAddressWithMmcuMovedAway) { expect_data_loaded("data_init"); }

// simavr's documented AVR_MCU() with default linking puts .mmcu between
// .text and .data; simavr's own loader then copied .data from the wrong
// place and the firmware sent ff ff ff.
TEST(ElfLoading, DataLoadsFromItsLoadAddressWithMmcuInItsDefaultPlace) { expect_data_loaded("data_init_mmcu_default"); }

std::string slurp_binary(const std::string& path) { return test::slurp(path); }

template <class T>
T& at(std::string& bytes, std::size_t offset) {
    return *reinterpret_cast<T*>(bytes.data() + offset);
}

// A valid ELF of ours, patched one way per case.
struct Mutation {
    const char* name;
    void (*apply)(std::string& elf);
    const char* message;  // part of the one-line error
};

Elf32_Shdr& section(std::string& elf, const char* wanted) {
    auto& eh = at<Elf32_Ehdr>(elf, 0);
    auto& names = at<Elf32_Shdr>(elf, eh.e_shoff + eh.e_shstrndx * sizeof(Elf32_Shdr));
    for (int i = 0; i < eh.e_shnum; ++i) {
        auto& sh = at<Elf32_Shdr>(elf, eh.e_shoff + static_cast<std::size_t>(i) * sizeof(Elf32_Shdr));
        if (std::strcmp(elf.data() + names.sh_offset + sh.sh_name, wanted) == 0) return sh;
    }
    throw std::runtime_error(std::string("no section ") + wanted);
}

const Mutation kMutations[] = {
    {"symtab_entsize_0", [](std::string& e) { section(e, ".symtab").sh_entsize = 0; }, "symbol table entries of 0 bytes"},
    {"section_name_out_of_range", [](std::string& e) { section(e, ".text").sh_name = 0x7fffffff; }, "has its name outside the name table"},
    {"symbol_name_out_of_range",
     [](std::string& e) {
         auto& st = section(e, ".symtab");
         at<Elf32_Sym>(e, st.sh_offset + 5 * sizeof(Elf32_Sym)).st_name = 0x7fffffff;
     },
     "has its name outside the string table"},
    {"mmcu_tag_too_long",
     [](std::string& e) {
         auto& mm = section(e, ".mmcu");
         // {0,0} end marker, then the frequency tag {2, 4, ...}: claim 255 bytes.
         e[mm.sh_offset + 3] = static_cast<char>(0xff);
     },
     "malformed .mmcu section"},
    {"mmcu_name_unterminated",
     [](std::string& e) {
         auto& mm = section(e, ".mmcu");
         // The name tag {1, 64, "atmega328p\0..."} follows at byte 8: fill all 64 bytes.
         std::memset(e.data() + mm.sh_offset + 10, 'a', 64);
     },
     "the MCU name is empty, unterminated or longer than 63 characters"},
    {"relocatable_object", [](std::string& e) { at<Elf32_Ehdr>(e, 0).e_type = ET_REL; }, "not an AVR executable"},
    {"segment_outside_file",
     [](std::string& e) {
         auto& eh = at<Elf32_Ehdr>(e, 0);
         at<Elf32_Phdr>(e, eh.e_phoff).p_offset = 0x7ffffff0;
     },
     "segment 0 lies outside the file"},
    {"segment_beyond_flash",
     [](std::string& e) {
         auto& eh = at<Elf32_Ehdr>(e, 0);
         at<Elf32_Phdr>(e, eh.e_phoff).p_paddr = 0x7ffff0;
     },
     "does not fit any AVR flash"},
    {"truncated", [](std::string& e) { e.resize(e.size() / 2); }, "truncated"},
    {"not_avr", [](std::string& e) { at<Elf32_Ehdr>(e, 0).e_machine = EM_386; }, "not an AVR ELF"},
};

TEST(ElfLoading, MalformedFilesAreOneLineWithExitCode2) {
    const auto dir = test::scratch_dir("bad-elf");
    const std::string original = slurp_binary(test::firmware("data_init_mmcu_default"));
    for (const auto& m : kMutations) {
        std::string bytes = original;
        m.apply(bytes);
        const fs::path path = dir / (std::string(m.name) + ".elf");
        std::ofstream(path, std::ios::binary) << bytes;
        const auto r = test::run_command(std::string(::avrbench::test::cli()) + " run -q " + path.string() + " --for 1ms", dir, 20);
        EXPECT_EQ(r.exit_code, 2) << m.name << ": " << r.out << r.err;
        EXPECT_EQ(r.err.rfind("avrbench: error: " + path.string() + ": ", 0), 0u) << m.name << ": " << r.err;
        EXPECT_NE(r.err.find(m.message), std::string::npos) << m.name << ": " << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << m.name << ": " << r.err;
    }
}

}  // namespace
}  // namespace avrbench
