// A FAT file system on a card's blocks, as the firmware on the card's other
// side sees it (Microsoft "FAT: General Overview of On-Disk Format" 1.03,
// the layout mkfs.vfat writes): made from a folder's files for an sd_card,
// and read back so the bench knows what a firmware printing a file from the
// card was told to do. Only the root directory and 8.3 names: what an AVR
// firmware's SD library lists (Marlin's and Prusa's SdFat read long names,
// but every file also has its 8.3 one).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace avrbench {

struct FatFile {
    std::string name;   // "JOB.GCO": the 8.3 name as the directory holds it, "." between its parts
    std::string bytes;
};

// A 32 MiB FAT16 volume without a partition table (as `mkfs.vfat -C img
// 32768` makes: 512-byte sectors, 4 per cluster, 2 FATs, 512 root entries)
// holding `files` in its root directory in the given order, every date
// 2020-01-01 so the same files give the same bytes. A name that is not 8.3
// (base up to 8 and extension up to 3 of A-Z 0-9 $ % ' - _ @ ~ ` ! ( ) { } ^ # &,
// upper case or lower) or files beyond the volume throw BadInput naming `what`.
std::vector<std::uint8_t> make_fat16_volume(const std::vector<FatFile>& files, const std::string& what);

// The files in the root directory of the FAT12/16/32 volume at the start of
// `blocks` or in its first MBR partition; empty when there is none (no boot
// signature, not a FAT BPB) or its structures point outside the image.
std::optional<std::vector<FatFile>> read_fat_root_files(const std::vector<std::uint8_t>& blocks);

}  // namespace avrbench
