#include "core/ElfImage.hpp"

#include <fcntl.h>
#include <gelf.h>
#include <libelf.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string_view>

extern "C" {
#include <sim_elf.h>
}

#include "core/Errors.hpp"
#include "core/SimavrLog.hpp"

namespace avrbench {
namespace {

// The GNU AVR linker maps data space at 0x800000 and EEPROM at 0x810000 in its
// flat address space (avr-libc linker scripts); flash starts at 0.
constexpr std::uint32_t kDataSpaceBase = 0x800000;

void free_firmware(elf_firmware_t* fw) {
    if (fw == nullptr) return;
    std::free(fw->flash);
    std::free(fw->eeprom);
    std::free(fw->fuse);
    std::free(fw->lockbits);
    for (std::uint32_t i = 0; i < fw->symbolcount; ++i) std::free(fw->symbol[i]);
    std::free(fw->symbol);
    delete fw;
}

// Several names often share an address: avr-libc aliases every unused
// __vector_N to __bad_interrupt, and __vectors, __vector_default and
// __heap_end all sit at 0. The most telling name wins.
int name_rank(const char* name, int type) {
    const std::string_view n(name);
    if (n == "__bad_interrupt" || n == "__vectors") return 3;
    if (n.rfind("__vector_", 0) == 0 || n == "__heap_end") return 0;
    return type == STT_FUNC ? 2 : 1;
}

struct ElfHandle {
    int fd = -1;
    Elf* elf = nullptr;
    ~ElfHandle() {
        if (elf != nullptr) elf_end(elf);
        if (fd >= 0) close(fd);
    }
};

}  // namespace

ElfImage ElfImage::load(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw BadInput(path + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) throw BadInput(path + ": not a regular file");

    install_simavr_log_router();
    if (elf_version(EV_CURRENT) == EV_NONE) throw BadInput("libelf: version mismatch");
    ElfHandle h;
    h.fd = open(path.c_str(), O_RDONLY);
    if (h.fd < 0) throw BadInput(path + ": cannot open: " + std::strerror(errno));
    h.elf = elf_begin(h.fd, ELF_C_READ, nullptr);
    if (h.elf == nullptr || elf_kind(h.elf) != ELF_K_ELF) throw BadInput(path + ": not an ELF file");
    GElf_Ehdr ehdr;
    if (gelf_getehdr(h.elf, &ehdr) == nullptr) throw BadInput(path + ": not an ELF file (unreadable header)");
    if (ehdr.e_machine != EM_AVR) {
        throw BadInput(path + ": not an AVR ELF (e_machine " + std::to_string(ehdr.e_machine) +
                       ", expected " + std::to_string(EM_AVR) + ")");
    }
    if (gelf_getclass(h.elf) != ELFCLASS32) throw BadInput(path + ": not an AVR ELF (not ELF32)");

    ElfImage image;
    image.path_ = path;

    bool has_text = false;
    Elf_Scn* scn = nullptr;
    while ((scn = elf_nextscn(h.elf, scn)) != nullptr) {
        GElf_Shdr shdr;
        if (gelf_getshdr(scn, &shdr) == nullptr) continue;
        const char* name = elf_strptr(h.elf, ehdr.e_shstrndx, shdr.sh_name);
        if (name != nullptr && std::strcmp(name, ".text") == 0 && shdr.sh_size > 0) has_text = true;
        if (shdr.sh_type != SHT_SYMTAB) continue;
        Elf_Data* data = elf_getdata(scn, nullptr);
        if (data == nullptr || shdr.sh_entsize == 0) continue;
        const auto count = shdr.sh_size / shdr.sh_entsize;
        for (std::size_t i = 0; i < count; ++i) {
            GElf_Sym sym;
            if (gelf_getsym(data, static_cast<int>(i), &sym) == nullptr) continue;
            const char* sname = elf_strptr(h.elf, shdr.sh_link, sym.st_name);
            if (sname == nullptr || sname[0] == '\0' || sname[0] == '.') continue;
            const auto value = static_cast<std::uint32_t>(sym.st_value);
            image.symbols_.emplace(sname, value);
            const int type = GELF_ST_TYPE(sym.st_info);
            const bool in_flash = value < kDataSpaceBase && sym.st_shndx != SHN_ABS && sym.st_shndx != SHN_UNDEF;
            if (in_flash && (type == STT_FUNC || type == STT_NOTYPE)) {
                auto [it, inserted] = image.flash_functions_.emplace(value, sname);
                if (!inserted && name_rank(sname, type) > name_rank(it->second.c_str(), STT_NOTYPE)) it->second = sname;
            }
        }
    }
    if (!has_text) throw BadInput(path + ": AVR ELF without a .text section (nothing to run)");

    for (const char* end_symbol : {"__bss_end", "__noinit_end", "_end"}) {
        auto it = image.symbols_.find(end_symbol);
        if (it != image.symbols_.end() && it->second >= kDataSpaceBase && it->second < kDataSpaceBase + 0x10000) {
            image.ram_static_end_ = std::max(image.ram_static_end_, it->second - kDataSpaceBase);
        }
    }

    // Only now, with the file known to be a sane AVR ELF, let simavr parse it
    // (its parser trusts its input).
    image.firmware_ = std::shared_ptr<elf_firmware_t>(new elf_firmware_t{}, free_firmware);
    if (elf_read_firmware(path.c_str(), image.firmware_.get()) != 0) {
        throw BadInput(path + ": simavr could not read this ELF");
    }
    image.embedded_mcu_ = image.firmware_->mmcu;
    image.embedded_frequency_hz_ = image.firmware_->frequency;
    return image;
}

std::optional<std::uint32_t> ElfImage::symbol_address(const std::string& name) const {
    auto it = symbols_.find(name);
    if (it == symbols_.end()) return std::nullopt;
    return it->second;
}

std::string ElfImage::describe_flash_address(std::uint32_t pc_bytes) const {
    char buf[96];
    auto it = flash_functions_.upper_bound(pc_bytes);
    if (it == flash_functions_.begin()) {
        std::snprintf(buf, sizeof buf, "0x%04x", pc_bytes);
        return buf;
    }
    --it;
    const std::uint32_t offset = pc_bytes - it->first;
    if (offset == 0) return it->second;
    std::snprintf(buf, sizeof buf, "+0x%x", offset);
    return it->second + buf;
}

}  // namespace avrbench
