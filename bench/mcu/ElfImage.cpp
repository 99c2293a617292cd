#include "mcu/ElfImage.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <gelf.h>
#include <libelf.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string_view>
#include <vector>

extern "C" {
#include <sim_elf.h>
}

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "core/Units.hpp"
#include "core/SimavrLog.hpp"

namespace avrbench {
namespace {

// The GNU AVR linker maps data space at 0x800000 and EEPROM at 0x810000 in its
// flat address space (avr-libc linker scripts); flash starts at 0.
constexpr std::uint32_t kDataSpaceBase = 0x800000;
constexpr std::uint32_t kEepromBase = 0x810000;
constexpr std::uint32_t kFuseBase = 0x820000;
constexpr std::uint32_t kLockBase = 0x830000;
constexpr std::uint32_t kSignatureBase = 0x840000;
// The largest AVR flash is 384 KiB (ATxmega384); 4 MiB bounds the image.
constexpr std::uint32_t kMaxFlashBytes = 4u << 20;
constexpr std::uint32_t kMaxEepromBytes = 64u << 10;
constexpr std::size_t kMaxFuseBytes = 6;  // simavr's avr_t::fuse[6]
// Symbol and string tables are read whole; Marlin 2 with debug info has ~1 MiB.
constexpr std::uint64_t kMaxSymbolTableBytes = 64u << 20;

// .mmcu tag numbers (simavr's avr_mcu_section.h, the format firmware writes).
enum MmcuTag : std::uint8_t {
    kTagEnd = 0, kTagName = 1, kTagFrequency = 2, kTagVcc = 3, kTagAvcc = 4, kTagAref = 5,
    kTagLowFuse = 6, kTagHighFuse = 7, kTagExtendedFuse = 8, kTagSignature = 9, kTagCommand = 10,
    kTagConsole = 11, kTagVcdFile = 12, kTagVcdPeriod = 13, kTagVcdTrace = 14, kTagVcdPortPin = 15,
    kTagVcdIrq = 16, kTagExternalPull = 17,
};
// avr_mmcu_vcd_trace_t minus its tag and length: mask (1), what (a 2-byte
// AVR pointer), name[32].
constexpr std::uint8_t kVcdTraceTagBytes = 35;

std::string hex(unsigned value) {
    char text[16];
    std::snprintf(text, sizeof text, "%X", value);
    return text;
}

std::uint32_t le32(const std::uint8_t* p) {
    return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
           (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
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

// The header of an AVR executable (ELF32, EM_AVR, ET_EXEC, headers inside the file).
void check_elf_header(Elf* elf, std::uint64_t file_size, const std::string& path) {
    GElf_Ehdr ehdr;
    if (gelf_getehdr(elf, &ehdr) == nullptr) throw BadInput(path + ": not an ELF file (unreadable header)");
    if (ehdr.e_machine != EM_AVR) {
        throw BadInput(path + ": not an AVR ELF (e_machine " + std::to_string(ehdr.e_machine) +
                       ", expected " + std::to_string(EM_AVR) + ")");
    }
    if (gelf_getclass(elf) != ELFCLASS32) throw BadInput(path + ": not an AVR ELF (not ELF32)");
    if (ehdr.e_shoff + static_cast<std::uint64_t>(ehdr.e_shnum) * ehdr.e_shentsize > file_size ||
        ehdr.e_phoff + static_cast<std::uint64_t>(ehdr.e_phnum) * ehdr.e_phentsize > file_size) {
        throw BadInput(path + ": malformed ELF: truncated (its headers reach past the end of the file)");
    }
    if (ehdr.e_type != ET_EXEC) throw BadInput(path + ": not an AVR executable (an object file or library? link it first)");
}

// The .mmcu section's bytes (simavr's tags), bounded.
std::vector<std::uint8_t> mmcu_section(Elf_Scn* scn, const GElf_Shdr& shdr, const std::string& path) {
    if (shdr.sh_size > 4096) throw BadInput(path + ": malformed .mmcu section (" + std::to_string(shdr.sh_size) + " bytes; simavr tags take a few hundred)");
    Elf_Data* data = elf_getdata(scn, nullptr);
    if (data == nullptr || data->d_buf == nullptr || data->d_size != shdr.sh_size) {
        throw BadInput(path + ": malformed ELF: the .mmcu section's bytes lie outside the file");
    }
    const auto* bytes = static_cast<const std::uint8_t*>(data->d_buf);
    return {bytes, bytes + data->d_size};
}

// Every named symbol, and the flash ones that can name a PC (functions and labels).
void read_symbol_table(Elf* elf, Elf_Scn* scn, const GElf_Shdr& shdr, const std::string& path,
                       std::map<std::string, std::uint32_t>& symbols, std::map<std::uint32_t, std::string>& functions,
                       std::map<std::string, std::uint32_t>& object_sizes) {
    // A symbol table, and the string table it names, are read whole: bounded.
    GElf_Shdr strings{};
    Elf_Scn* string_section = elf_getscn(elf, shdr.sh_link);
    if (shdr.sh_size > kMaxSymbolTableBytes || string_section == nullptr || gelf_getshdr(string_section, &strings) == nullptr ||
        strings.sh_size > kMaxSymbolTableBytes) {
        throw BadInput(path + ": malformed ELF: a symbol table or its names larger than " +
                       std::to_string(kMaxSymbolTableBytes >> 20) + " MiB, or without its string table");
    }
    if (shdr.sh_entsize != sizeof(Elf32_Sym)) {
        throw BadInput(path + ": malformed ELF: symbol table entries of " + std::to_string(shdr.sh_entsize) +
                       " bytes (ELF32 symbols are " + std::to_string(sizeof(Elf32_Sym)) + ")");
    }
    Elf_Data* data = elf_getdata(scn, nullptr);
    if (data == nullptr) throw BadInput(path + ": malformed ELF: the symbol table lies outside the file");
    const auto count = data->d_size / sizeof(Elf32_Sym);
    for (std::size_t i = 0; i < count && i < 1'000'000; ++i) {
        GElf_Sym sym;
        if (gelf_getsym(data, static_cast<int>(i), &sym) == nullptr) continue;
        const char* sname = elf_strptr(elf, shdr.sh_link, sym.st_name);
        if (sname == nullptr) {
            throw BadInput(path + ": malformed ELF: symbol " + std::to_string(i) + " has its name outside the string table");
        }
        if (sname[0] == '\0' || sname[0] == '.') continue;
        const auto value = static_cast<std::uint32_t>(sym.st_value);
        symbols.emplace(sname, value);
        const int type = GELF_ST_TYPE(sym.st_info);
        if (type == STT_OBJECT && sym.st_size > 0) object_sizes.emplace(sname, static_cast<std::uint32_t>(sym.st_size));
        const bool in_flash = value < kDataSpaceBase && sym.st_shndx != SHN_ABS && sym.st_shndx != SHN_UNDEF;
        if (in_flash && (type == STT_FUNC || type == STT_NOTYPE)) {
            auto [it, inserted] = functions.emplace(value, sname);
            if (!inserted && name_rank(sname, type) > name_rank(it->second.c_str(), STT_NOTYPE)) it->second = sname;
        }
    }
}

}  // namespace

ElfImage ElfImage::load(const std::string& path_given) {
    // Only the ELF's headers, the sections named below and the loadable
    // segments are read (libelf reads on demand): a file of gigabytes, a
    // sparse one or one with huge debug sections costs no more memory than
    // its program.
    const std::string path = escaped(path_given);
    install_simavr_log_router();
    if (elf_version(EV_CURRENT) == EV_NONE) throw BadInput("libelf: version mismatch");
    ElfHandle h;
    // A regular file, named as what it is otherwise (a FIFO is never opened for a blocking read).
    check_input_file(path_given, "firmware ELF", std::numeric_limits<std::uint64_t>::max());
    h.fd = open(path_given.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (h.fd < 0) throw BadInput(path + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (fstat(h.fd, &st) != 0 || !S_ISREG(st.st_mode)) throw BadInput(path + ": not a regular file");
    const auto file_size = static_cast<std::uint64_t>(st.st_size);
    h.elf = elf_begin(h.fd, ELF_C_READ, nullptr);
    if (h.elf == nullptr || elf_kind(h.elf) != ELF_K_ELF) throw BadInput(path + ": not an ELF file");
    check_elf_header(h.elf, file_size, path);

    ElfImage image;
    image.path_ = path_given;
    image.flash_ = std::make_shared<std::vector<std::uint8_t>>();
    image.eeprom_ = std::make_shared<std::vector<std::uint8_t>>();

    std::size_t shstrndx = 0;
    if (elf_getshdrstrndx(h.elf, &shstrndx) != 0) throw BadInput(path + ": malformed ELF: no section-name table");
    bool has_text = false;
    std::vector<std::uint8_t> mmcu_bytes;
    const std::vector<std::uint8_t>* mmcu = nullptr;
    Elf_Scn* scn = nullptr;
    while ((scn = elf_nextscn(h.elf, scn)) != nullptr) {
        GElf_Shdr shdr;
        if (gelf_getshdr(scn, &shdr) == nullptr) throw BadInput(path + ": malformed ELF: unreadable section header");
        const char* name = elf_strptr(h.elf, shstrndx, shdr.sh_name);
        if (name == nullptr) {
            throw BadInput(path + ": malformed ELF: section " + std::to_string(elf_ndxscn(scn)) + " has its name outside the name table");
        }
        if (std::strcmp(name, ".text") == 0 && shdr.sh_size > 0) {
            has_text = true;
            if (shdr.sh_addr + shdr.sh_size > kMaxFlashBytes) throw BadInput(path + ": .text lies outside any AVR flash");
            image.text_end_ = static_cast<std::uint32_t>(shdr.sh_addr + shdr.sh_size);
        }
        if (std::strcmp(name, ".mmcu") == 0 && shdr.sh_type == SHT_PROGBITS) {
            mmcu_bytes = mmcu_section(scn, shdr, path);
            mmcu = &mmcu_bytes;
        }
        if (shdr.sh_type == SHT_SYMTAB) read_symbol_table(h.elf, scn, shdr, path, image.symbols_, image.flash_functions_, image.object_sizes_);
    }
    if (!has_text) throw BadInput(path + ": AVR ELF without a .text section (nothing to run)");

    for (const char* end_symbol : {"__bss_end", "__noinit_end", "_end"}) {
        auto it = image.symbols_.find(end_symbol);
        if (it != image.symbols_.end() && it->second >= kDataSpaceBase && it->second < kDataSpaceBase + 0x10000) {
            image.ram_static_end_ = std::max(image.ram_static_end_, it->second - kDataSpaceBase);
        }
    }

    load_segments(h.elf, h.fd, file_size, path, image);
    if (mmcu != nullptr) parse_mmcu(*mmcu, path, image);
    return image;
}

// Flash, EEPROM, fuses and lock bits from the loadable segments, each at its
// load address in the linker's flat AVR address map.
void ElfImage::load_segments(Elf* elf, int fd, std::uint64_t file_size, const std::string& path, ElfImage& image) {
    std::size_t count = 0;
    if (elf_getphdrnum(elf, &count) != 0) throw BadInput(path + ": malformed ELF: unreadable program headers");
    if (count == 0) throw BadInput(path + ": not an AVR executable (no loadable segments)");
    struct Piece {
        std::uint32_t address;
        const std::uint8_t* bytes;
        std::uint32_t size;
    };
    // The bytes of the segments that are memory (flash, EEPROM, fuses, lock
    // bits), read when a segment's place is known: each is within an AVR
    // memory's size, so this is bounded too.
    std::vector<std::vector<std::uint8_t>> contents;
    contents.reserve(count);
    const auto read_segment = [&](const GElf_Phdr& ph) {
        std::vector<std::uint8_t>& bytes = contents.emplace_back(static_cast<std::size_t>(ph.p_filesz));
        std::size_t done = 0;
        while (done < bytes.size()) {
            const ssize_t n = pread(fd, bytes.data() + done, bytes.size() - done, static_cast<off_t>(ph.p_offset + done));
            if (n <= 0) throw BadInput(path + ": cannot read a segment: " + (n < 0 ? std::strerror(errno) : "the file ended"));
            done += static_cast<std::size_t>(n);
        }
        return bytes.data();
    };
    std::vector<Piece> flash, eeprom;
    for (std::size_t i = 0; i < count; ++i) {
        GElf_Phdr ph;
        if (gelf_getphdr(elf, static_cast<int>(i), &ph) == nullptr) throw BadInput(path + ": malformed ELF: unreadable program header");
        if (ph.p_type != PT_LOAD || ph.p_filesz == 0) continue;
        if (ph.p_offset > file_size || ph.p_filesz > file_size - ph.p_offset) {
            throw BadInput(path + ": malformed ELF: segment " + std::to_string(i) + " lies outside the file");
        }
        const std::uint64_t start = ph.p_paddr, end = ph.p_paddr + ph.p_filesz;
        auto inside = [&](std::uint64_t base, std::uint64_t limit) { return start >= base && end <= base + limit; };
        const bool memory = inside(0, kMaxFlashBytes) || inside(kEepromBase, kMaxEepromBytes) ||
                            (start == kFuseBase && ph.p_filesz <= kMaxFuseBytes) || (start == kLockBase && ph.p_filesz <= 1);
        const Piece piece{static_cast<std::uint32_t>(start), memory ? read_segment(ph) : nullptr, static_cast<std::uint32_t>(ph.p_filesz)};
        char where[96];
        std::snprintf(where, sizeof where, "segment %zu (load address 0x%llx, %llu bytes)", i,
                      static_cast<unsigned long long>(start), static_cast<unsigned long long>(ph.p_filesz));
        if (inside(0, kMaxFlashBytes)) {
            flash.push_back(piece);
        } else if (inside(kEepromBase, kMaxEepromBytes)) {
            eeprom.push_back({piece.address - kEepromBase, piece.bytes, piece.size});
        } else if (start >= kFuseBase && start < kFuseBase + 0x10000) {
            if (start != kFuseBase || ph.p_filesz > kMaxFuseBytes) {
                throw BadInput(path + ": malformed fuses: " + where + "; an AVR has at most " + std::to_string(kMaxFuseBytes) + " fuse bytes at 0x820000");
            }
            image.fuses_.assign(piece.bytes, piece.bytes + piece.size);
        } else if (start >= kLockBase && start < kLockBase + 0x10000) {
            if (start != kLockBase || ph.p_filesz > 1) throw BadInput(path + ": malformed lock bits: " + where + "; one byte at 0x830000");
            image.lock_bits_ = piece.bytes[0];
        } else if (start >= kSignatureBase && start < kSignatureBase + 0x10000) {
            // The signature is the chip's; the bench takes the MCU's own.
        } else if (start >= kDataSpaceBase && start < kEepromBase) {
            throw BadInput(path + ": malformed ELF: " + where + " loads into RAM directly; .data must load from flash");
        } else {
            // Other tags (simavr's .mmcu moved to 0x910000) are metadata, not memory.
            if (start < kDataSpaceBase) throw BadInput(path + ": " + where + " does not fit any AVR flash");
        }
    }
    if (flash.empty()) throw BadInput(path + ": no program: no loadable segment in the flash address range");
    std::uint32_t lo = flash.front().address, hi = 0;
    for (const auto& p : flash) {
        lo = std::min(lo, p.address);
        hi = std::max(hi, p.address + p.size);
    }
    // Unprogrammed flash reads 0xFF (an erased cell), as on the chip.
    image.flash_base_ = lo;
    image.flash_->assign(hi - lo, 0xFF);
    for (const auto& p : flash) std::memcpy(image.flash_->data() + (p.address - lo), p.bytes, p.size);
    std::uint32_t ee_end = 0;
    for (const auto& p : eeprom) ee_end = std::max(ee_end, p.address + p.size);
    image.eeprom_->assign(ee_end, 0xFF);
    for (const auto& p : eeprom) std::memcpy(image.eeprom_->data() + p.address, p.bytes, p.size);
}

// simavr's .mmcu tags: {tag, length, payload[length]}... to the section's
// end, in link order (AVR_MCU's {0, 0} end marker often comes first).
// Every length is checked against what is left.
void ElfImage::parse_mmcu(const std::vector<std::uint8_t>& section, const std::string& path, ElfImage& image) {
    std::size_t at = 0;
    while (at + 2 <= section.size()) {
        const std::uint8_t tag = section[at], length = section[at + 1];
        const std::size_t payload = at + 2;
        if (payload + length > section.size()) {
            throw BadInput(path + ": malformed .mmcu section: tag " + std::to_string(tag) + " at byte " + std::to_string(at) +
                           " claims " + std::to_string(length) + " bytes, " + std::to_string(section.size() - payload) + " remain");
        }
        const std::uint8_t* p = section.data() + payload;
        auto need = [&](std::size_t bytes, const char* what) {
            if (length < bytes) {
                throw BadInput(path + ": malformed .mmcu section: " + std::string(what) + " tag of " + std::to_string(length) + " bytes");
            }
        };
        switch (tag) {
            case kTagName: {
                std::size_t n = 0;
                while (n < length && p[n] != 0) ++n;
                if (n == length || n == 0 || n >= 64) throw BadInput(path + ": malformed .mmcu section: the MCU name is empty, unterminated or longer than 63 characters");
                for (std::size_t k = 0; k < n; ++k) {
                    if (!std::isalnum(p[k]) && p[k] != '_') throw BadInput(path + ": malformed .mmcu section: the MCU name has a character that is not a letter or digit");
                }
                image.embedded_mcu_.assign(reinterpret_cast<const char*>(p), n);
                break;
            }
            case kTagFrequency: {
                need(4, "frequency");
                const std::uint32_t hz = le32(p);
                if (hz < kMinClockHz || hz > kMaxClockHz) {
                    throw BadInput(path + ": .mmcu section: frequency " + std::to_string(hz) +
                                   " Hz is outside 1 Hz .. 64 MHz (the range --freq accepts)");
                }
                image.embedded_frequency_hz_ = hz;
                break;
            }
            case kTagVcc: need(4, "VCC"); image.vcc_mv_ = le32(p); break;
            case kTagAvcc: need(4, "AVCC"); image.avcc_mv_ = le32(p); break;
            case kTagAref: need(4, "AREF"); image.aref_mv_ = le32(p); break;
            case kTagExternalPull:
                need(3, "external pull");
                if (image.external_pulls_.size() >= 8) throw BadInput(path + ": malformed .mmcu section: more than 8 external pull tags");
                if (p[2] < 'A' || p[2] > 'L') throw BadInput(path + ": malformed .mmcu section: external pull on port '" + std::to_string(p[2]) + "'");
                image.external_pulls_.push_back({static_cast<char>(p[2]), p[1], p[0]});
                break;
            case kTagConsole: {
                need(2, "console register");
                const auto address = static_cast<std::uint16_t>(p[0] | (p[1] << 8));
                // simavr hooks it as an I/O register write: data addresses 0x20..0xff.
                if (address < 0x20 || address > 0xff) {
                    throw BadInput(path + ": malformed .mmcu section: console register 0x" + hex(address) + " is not an I/O register");
                }
                image.console_register_ = address;
                break;
            }
            case kTagLowFuse:
            case kTagHighFuse:
            case kTagExtendedFuse:
                // Ignored: the fuses come from the ELF's .fuse segment
                // (avr-libc's FUSES), as avrdude would program them.
                need(1, "fuse");
                break;
            case kTagSignature:
                // Ignored: the signature is the MCU type's own.
                need(3, "signature");
                break;
            case kTagCommand: {
                // Ignored (the bench has no command register; the firmware's
                // writes to it stay plain I/O writes), but it must name one.
                need(2, "command register");
                const auto address = static_cast<std::uint16_t>(p[0] | (p[1] << 8));
                if (address < 0x20 || address > 0xff) {
                    throw BadInput(path + ": malformed .mmcu section: command register 0x" + hex(address) + " is not an I/O register");
                }
                break;
            }
            case kTagVcdFile:
            case kTagVcdPeriod:
                // Ignored: --vcd names the file; every change is recorded.
                break;
            case kTagVcdTrace:
            case kTagVcdPortPin:
            case kTagVcdIrq:
                // Ignored: the bench's recorder is the trace (--trace, boards).
                // The struct is {mask, 2-byte address, 32-byte name} on AVR.
                if (length != kVcdTraceTagBytes) {
                    throw BadInput(path + ": malformed .mmcu section: a VCD trace tag of " + std::to_string(length) +
                                   " bytes (simavr's avr_mmcu_vcd_trace_t has " + std::to_string(kVcdTraceTagBytes) + ")");
                }
                break;
            case kTagEnd:
                break;
            default:
                // A tag simavr 1.6 does not define: the bench cannot know what it asks for.
                throw BadInput(path + ": malformed .mmcu section: unknown tag " + std::to_string(tag) + " at byte " +
                               std::to_string(at) + " (simavr 1.6's avr_mcu_section.h defines 0 to 17)");
        }
        at = payload + length;
    }
    if (at != section.size()) {
        throw BadInput(path + ": malformed .mmcu section: " + std::to_string(section.size() - at) +
                       " byte(s) after its last tag (a tag is at least 2 bytes)");
    }
}

elf_firmware_t ElfImage::simavr_firmware() const {
    elf_firmware_t fw{};
    std::snprintf(fw.mmcu, sizeof fw.mmcu, "%s", embedded_mcu_.c_str());
    fw.frequency = embedded_frequency_hz_;
    fw.vcc = vcc_mv_;
    fw.avcc = avcc_mv_;
    fw.aref = aref_mv_;
    fw.flashbase = flash_base_;
    fw.flash = flash_->data();
    fw.flashsize = static_cast<std::uint32_t>(flash_->size());
    // simavr takes codeend = flashbase + flashsize - datasize: make it .text's end.
    const std::uint32_t flash_end = flash_base_ + fw.flashsize;
    fw.datasize = text_end_ != 0 && text_end_ <= flash_end && text_end_ >= flash_base_ ? flash_end - text_end_ : 0;
    if (!eeprom_->empty()) {
        fw.eeprom = eeprom_->data();
        fw.eesize = static_cast<std::uint32_t>(eeprom_->size());
    }
    if (!fuses_.empty()) {
        fw.fuse = const_cast<std::uint8_t*>(fuses_.data());  // simavr only reads it
        fw.fusesize = static_cast<std::uint32_t>(fuses_.size());
    }
    if (lock_bits_) fw.lockbits = const_cast<std::uint8_t*>(&*lock_bits_);
    for (std::size_t i = 0; i < external_pulls_.size() && i < 8; ++i) {
        fw.external_state[i].port = external_pulls_[i].port;
        fw.external_state[i].mask = external_pulls_[i].mask;
        fw.external_state[i].value = external_pulls_[i].value;
    }
    fw.console_register_addr = console_register_;
    return fw;
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
