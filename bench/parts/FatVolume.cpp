#include "parts/FatVolume.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>

#include "core/Errors.hpp"

namespace avrbench {

namespace {

constexpr std::size_t kSector = 512;
constexpr std::size_t kDirEntry = 32;

// The FAT16 volume make_fat16_volume writes: 65 536 sectors; 1 reserved; two
// FATs of 64 sectors (16 343 clusters * 2 bytes + 4 fit in 32 768 bytes);
// 512 root entries = 32 sectors; data from sector 161, 4 sectors a cluster.
constexpr std::uint32_t kTotalSectors = 65536;
constexpr std::uint16_t kReservedSectors = 1;
constexpr std::uint8_t kFatCount = 2;
constexpr std::uint16_t kFatSectors = 64;
constexpr std::uint16_t kRootEntries = 512;
constexpr std::uint8_t kSectorsPerCluster = 4;
constexpr std::uint32_t kRootSector = kReservedSectors + kFatCount * kFatSectors;
constexpr std::uint32_t kDataSector = kRootSector + kRootEntries * kDirEntry / kSector;
constexpr std::uint32_t kClusters = (kTotalSectors - kDataSector) / kSectorsPerCluster;
// 2020-01-01 00:00 in FAT's date format: (year - 1980) << 9 | month << 5 | day.
constexpr std::uint16_t kDate = (2020 - 1980) << 9 | 1 << 5 | 1;

void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
    b[at] = static_cast<std::uint8_t>(v);
    b[at + 1] = static_cast<std::uint8_t>(v >> 8);
}
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
    put16(b, at, v & 0xFFFF);
    put16(b, at + 2, v >> 16);
}
std::uint32_t get16(const std::vector<std::uint8_t>& b, std::size_t at) { return b[at] | b[at + 1] << 8; }
std::uint32_t get32(const std::vector<std::uint8_t>& b, std::size_t at) { return get16(b, at) | get16(b, at + 2) << 16; }

bool short_name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0 || std::strchr("$%'-_@~`!(){}^#&", c) != nullptr;
}

// "job.gco" -> "JOB     GCO"; empty when it is no 8.3 name.
std::string short_name_of(const std::string& name) {
    const std::size_t dot = name.find('.');
    const std::string base = name.substr(0, dot);
    const std::string ext = dot == std::string::npos ? "" : name.substr(dot + 1);
    if (base.empty() || base.size() > 8 || ext.size() > 3 || (dot != std::string::npos && ext.empty())) return {};
    if (!std::all_of(base.begin(), base.end(), short_name_char) || !std::all_of(ext.begin(), ext.end(), short_name_char)) return {};
    std::string out(11, ' ');
    for (std::size_t i = 0; i < base.size(); ++i) out[i] = static_cast<char>(std::toupper(static_cast<unsigned char>(base[i])));
    for (std::size_t i = 0; i < ext.size(); ++i) out[8 + i] = static_cast<char>(std::toupper(static_cast<unsigned char>(ext[i])));
    return out;
}

}  // namespace

std::vector<std::uint8_t> make_fat16_volume(const std::vector<FatFile>& files, const std::string& what) {
    if (files.size() > kRootEntries) {
        throw BadInput(what + ": " + std::to_string(files.size()) + " files, more than the root directory's " +
                       std::to_string(kRootEntries));
    }
    std::vector<std::uint8_t> v(static_cast<std::size_t>(kTotalSectors) * kSector, 0);
    // Boot sector and BPB (overview §3.1, §3.2): jump, OEM name, geometry.
    v[0] = 0xEB; v[1] = 0x3C; v[2] = 0x90;
    std::memcpy(&v[3], "AVRBENCH", 8);
    put16(v, 11, kSector);
    v[13] = kSectorsPerCluster;
    put16(v, 14, kReservedSectors);
    v[16] = kFatCount;
    put16(v, 17, kRootEntries);
    put16(v, 19, 0);  // more than 65 535 sectors: the count is in TotSec32
    v[21] = 0xF8;     // fixed media
    put16(v, 22, kFatSectors);
    put16(v, 24, 32);
    put16(v, 26, 64);
    put32(v, 28, 0);
    put32(v, 32, kTotalSectors);
    v[36] = 0x80;
    v[38] = 0x29;  // the volume ID, label and type follow
    put32(v, 39, 0x41564230);
    std::memcpy(&v[43], "NO NAME    ", 11);  // no label (a label here needs its root entry too)
    std::memcpy(&v[54], "FAT16   ", 8);
    v[510] = 0x55; v[511] = 0xAA;

    std::vector<std::uint16_t> fat(kClusters + 2, 0);
    fat[0] = 0xFFF8;  // the media byte in the low 8 bits
    fat[1] = 0xFFFF;
    constexpr std::size_t kClusterBytes = static_cast<std::size_t>(kSectorsPerCluster) * kSector;
    std::uint32_t next_cluster = 2;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < files.size(); ++i) {
        const FatFile& f = files[i];
        const std::string short_name = short_name_of(f.name);
        if (short_name.empty()) {
            throw BadInput(what + ": '" + f.name + "' is not an 8.3 name (up to 8 letters, digits or $%'-_@~`!(){}^#& "
                           "and an extension of up to 3; the card holds no long names)");
        }
        if (std::find(names.begin(), names.end(), short_name) != names.end()) {
            throw BadInput(what + ": '" + f.name + "' twice (names are upper-cased on the card)");
        }
        names.push_back(short_name);
        const std::uint32_t clusters = static_cast<std::uint32_t>((f.bytes.size() + kClusterBytes - 1) / kClusterBytes);
        if (next_cluster + clusters > kClusters + 2) throw BadInput(what + ": the files do not fit on the 32 MiB card");
        const std::uint32_t first = clusters == 0 ? 0 : next_cluster;
        for (std::uint32_t c = 0; c < clusters; ++c) {
            const std::uint32_t cluster = next_cluster + c;
            fat[cluster] = static_cast<std::uint16_t>(c + 1 == clusters ? 0xFFFF : cluster + 1);
            const std::size_t offset = c * kClusterBytes;
            const std::size_t n = std::min(kClusterBytes, f.bytes.size() - offset);
            std::memcpy(&v[(kDataSector + (cluster - 2) * kSectorsPerCluster) * kSector], f.bytes.data() + offset, n);
        }
        next_cluster += clusters;
        const std::size_t e = kRootSector * kSector + i * kDirEntry;
        std::memcpy(&v[e], short_name.data(), 11);
        v[e + 11] = 0x20;  // ARCHIVE
        put16(v, e + 16, kDate);
        put16(v, e + 18, kDate);
        put16(v, e + 24, kDate);
        put16(v, e + 26, first);
        put32(v, e + 28, static_cast<std::uint32_t>(f.bytes.size()));
    }
    for (std::uint8_t copy = 0; copy < kFatCount; ++copy) {
        const std::size_t at = (kReservedSectors + copy * kFatSectors) * kSector;
        for (std::size_t c = 0; c < fat.size(); ++c) put16(v, at + 2 * c, fat[c]);
    }
    return v;
}

std::optional<std::vector<FatFile>> read_fat_root_files(const std::vector<std::uint8_t>& blocks) {
    if (blocks.size() < kSector || blocks[510] != 0x55 || blocks[511] != 0xAA) return std::nullopt;
    auto is_bpb = [&](std::size_t at) {
        return at + kSector <= blocks.size() && (blocks[at] == 0xEB || blocks[at] == 0xE9) &&
               get16(blocks, at + 11) == kSector && blocks[at + 13] != 0 && blocks[at + 16] != 0;
    };
    // A volume from sector 0 (mkfs.vfat -C), or the first partition of an MBR.
    std::size_t base = 0;
    if (!is_bpb(0)) {
        base = static_cast<std::size_t>(get32(blocks, 446 + 8)) * kSector;
        if (!is_bpb(base)) return std::nullopt;
    }
    const std::uint32_t per_cluster = blocks[base + 13];
    const std::uint32_t reserved = get16(blocks, base + 14);
    const std::uint32_t fats = blocks[base + 16];
    const std::uint32_t root_entries = get16(blocks, base + 17);
    const std::uint32_t total = get16(blocks, base + 19) != 0 ? get16(blocks, base + 19) : get32(blocks, base + 32);
    const std::uint32_t fat_sectors = get16(blocks, base + 22) != 0 ? get16(blocks, base + 22) : get32(blocks, base + 36);
    const auto root_sectors = static_cast<std::uint32_t>((root_entries * kDirEntry + kSector - 1) / kSector);
    const std::uint64_t data = reserved + static_cast<std::uint64_t>(fats) * fat_sectors + root_sectors;
    if (total <= data) return std::nullopt;
    const std::uint64_t clusters = (total - data) / per_cluster;
    // The type follows from the cluster count alone (overview §3.5).
    const int bits = clusters < 4085 ? 12 : clusters < 65525 ? 16 : 32;
    const std::size_t fat_at = base + reserved * kSector;
    const std::size_t cluster_bytes = per_cluster * kSector;
    auto inside = [&](std::uint64_t at, std::uint64_t n) { return at + n <= blocks.size(); };
    auto next = [&](std::uint32_t c) -> std::optional<std::uint32_t> {
        const std::uint64_t at = bits == 12 ? fat_at + c + c / 2 : fat_at + static_cast<std::uint64_t>(c) * (bits / 8);
        if (!inside(at, bits == 32 ? 4 : 2)) return std::nullopt;
        if (bits == 12) return (c & 1) != 0 ? get16(blocks, at) >> 4 : get16(blocks, at) & 0xFFF;
        if (bits == 16) return get16(blocks, at);
        return get32(blocks, at) & 0x0FFFFFFF;
    };
    const std::uint32_t end_of_chain = bits == 12 ? 0xFF8 : bits == 16 ? 0xFFF8 : 0x0FFFFFF8;
    auto cluster_at = [&](std::uint32_t c) { return base + (data + static_cast<std::uint64_t>(c - 2) * per_cluster) * kSector; };
    // A chain's bytes, at most `limit`; empty when it leaves the volume or loops.
    auto chain = [&](std::uint32_t first, std::uint64_t limit) -> std::optional<std::string> {
        std::string out;
        std::uint32_t c = first;
        for (std::uint64_t hops = 0; c >= 2 && c < end_of_chain && out.size() < limit; ++hops) {
            if (hops > clusters || c - 2 >= clusters || !inside(cluster_at(c), cluster_bytes)) return std::nullopt;
            const auto* p = reinterpret_cast<const char*>(&blocks[cluster_at(c)]);
            out.append(p, std::min<std::uint64_t>(cluster_bytes, limit - out.size()));
            const auto n = next(c);
            if (!n) return std::nullopt;
            c = *n;
        }
        return out;
    };
    std::string root;
    if (bits == 32) {
        const auto r = chain(get32(blocks, base + 44), clusters * cluster_bytes);
        if (!r) return std::nullopt;
        root = *r;
    } else {
        const std::uint64_t at = base + (reserved + static_cast<std::uint64_t>(fats) * fat_sectors) * kSector;
        if (!inside(at, root_sectors * kSector)) return std::nullopt;
        root.assign(reinterpret_cast<const char*>(&blocks[at]), root_sectors * kSector);
    }
    std::vector<FatFile> files;
    for (std::size_t e = 0; e + kDirEntry <= root.size(); e += kDirEntry) {
        const auto first_byte = static_cast<unsigned char>(root[e]);
        if (first_byte == 0x00) break;  // no entries after this one
        const auto attributes = static_cast<unsigned char>(root[e + 11]);
        // Deleted, long-name pieces, the volume label and directories are no files.
        if (first_byte == 0xE5 || (attributes & 0x0F) == 0x0F || (attributes & 0x18) != 0) continue;
        auto trimmed = [](std::string s) { return s.erase(s.find_last_not_of(' ') + 1); };
        const std::string base_name = trimmed(root.substr(e, 8)), ext = trimmed(root.substr(e + 8, 3));
        const std::vector<std::uint8_t> entry(root.begin() + static_cast<std::ptrdiff_t>(e),
                                              root.begin() + static_cast<std::ptrdiff_t>(e + kDirEntry));
        const std::uint32_t first = get16(entry, 26) | (bits == 32 ? get16(entry, 20) << 16 : 0);
        const std::uint32_t size = get32(entry, 28);
        FatFile f{base_name + (ext.empty() ? "" : "." + ext), {}};
        if (size > 0) {
            const auto bytes = chain(first, size);
            if (!bytes || bytes->size() != size) return std::nullopt;
            f.bytes = *bytes;
        }
        files.push_back(std::move(f));
    }
    return files;
}

}  // namespace avrbench
