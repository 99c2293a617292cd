// Intel HEX images (the format avr-objcopy writes and bootloaders ship in,
// e.g. Debian's arduino-core-avr optiboot_atmega328.hex). The bench reads
// them itself rather than through simavr's read_ihex_chunks(): that one
// stops at a bad checksum and returns what it had read so far, and names
// neither the line nor the problem.
//
// Record types (Intel, "Hexadecimal Object File Format Specification",
// rev. A, 1988): 00 data, 01 end of file, 02 extended segment address
// (base = value << 4), 03 start segment address (ignored: AVRs start at
// their reset vector), 04 extended linear address (base = value << 16),
// 05 start linear address (ignored).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace avrbench {

struct HexChunk {
    std::uint32_t address = 0;  // byte address of the first byte
    std::vector<std::uint8_t> bytes;
};

// The data records merged into contiguous chunks, by address. Throws
// BadInput "file:line: ..." for a missing file, a line that is not a record,
// a wrong byte count or checksum, an unknown record type, data after the
// end-of-file record, overlapping data, or no end-of-file record.
std::vector<HexChunk> read_intel_hex(const std::string& path);

}  // namespace avrbench
