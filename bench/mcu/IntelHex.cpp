#include "mcu/IntelHex.hpp"

#include <cstdio>
#include <sstream>
#include <map>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

namespace avrbench {

namespace {

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

}  // namespace

std::vector<HexChunk> read_intel_hex(const std::string& path) {
    std::istringstream in(read_input_file(path, "Intel HEX file", kMaxBootloaderFileBytes));

    std::map<std::uint32_t, std::uint8_t> bytes;  // address -> byte, to find overlaps and merge
    std::uint32_t base = 0;
    bool ended = false;
    std::string line;
    for (unsigned number = 1; std::getline(in, line); ++number) {
        const std::string where = path + ":" + std::to_string(number) + ": ";
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        if (ended) throw BadInput(where + "data after the end-of-file record");
        if (line[0] != ':') throw BadInput(where + "not an Intel HEX record (a record starts with ':')");
        if (line.size() < 11 || line.size() % 2 == 0) throw BadInput(where + "record too short or of odd length");
        std::vector<std::uint8_t> record;
        for (std::size_t i = 1; i + 1 < line.size(); i += 2) {
            const int hi = hex_digit(line[i]), lo = hex_digit(line[i + 1]);
            if (hi < 0 || lo < 0) throw BadInput(where + "'" + line.substr(i, 2) + "' is not a hex byte");
            record.push_back(static_cast<std::uint8_t>(hi * 16 + lo));
        }
        const std::size_t count = record[0];
        if (record.size() != count + 5) {
            throw BadInput(where + "byte count " + std::to_string(count) + " does not match the record's " +
                           std::to_string(record.size() - 5) + " data bytes");
        }
        std::uint8_t sum = 0;
        for (const std::uint8_t b : record) sum = static_cast<std::uint8_t>(sum + b);
        if (sum != 0) throw BadInput(where + "checksum does not match (the record's bytes sum to " + std::to_string(sum) + ", not 0 mod 256)");
        const std::uint32_t offset = static_cast<std::uint32_t>(record[1] << 8 | record[2]);
        const std::uint8_t type = record[3];
        const std::uint8_t* data = record.data() + 4;
        switch (type) {
            case 0x00: {
                const std::uint32_t start = base + offset;
                for (std::size_t i = 0; i < count; ++i) {
                    if (!bytes.emplace(start + static_cast<std::uint32_t>(i), data[i]).second) {
                        char text[80];
                        std::snprintf(text, sizeof text, "data at 0x%05X was already given by an earlier record",
                                      static_cast<unsigned>(start + i));
                        throw BadInput(where + text);
                    }
                }
                break;
            }
            case 0x01: ended = true; break;
            case 0x02:
            case 0x04:
                if (count != 2) throw BadInput(where + "an address record (type 0" + std::to_string(type) + ") carries 2 bytes");
                base = static_cast<std::uint32_t>(data[0] << 8 | data[1]) << (type == 0x02 ? 4 : 16);
                break;
            case 0x03:
            case 0x05: break;
            default: throw BadInput(where + "unknown record type " + std::to_string(type) + " (expected 00 to 05)");
        }
    }
    if (!ended) throw BadInput(path + ": no end-of-file record (:00000001FF); the file is cut short");

    std::vector<HexChunk> chunks;
    for (const auto& [address, value] : bytes) {
        if (chunks.empty() || chunks.back().address + chunks.back().bytes.size() != address) {
            chunks.push_back(HexChunk{address, {}});
        }
        chunks.back().bytes.push_back(value);
    }
    return chunks;
}

}  // namespace avrbench
