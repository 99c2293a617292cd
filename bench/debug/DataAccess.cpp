#include "debug/DataAccess.hpp"

namespace avrbench {

namespace {

std::uint16_t pair_at(const std::uint8_t* data, unsigned low) {
    return static_cast<std::uint16_t>(data[low] | (data[low + 1] << 8));
}
constexpr unsigned kX = 26, kY = 28, kZ = 30;
constexpr unsigned kSpl = 0x5D;

}  // namespace

std::vector<DataAccess> data_accesses(std::uint16_t opcode, std::uint16_t next, const std::uint8_t* data) {
    const auto at = [](unsigned address, bool write) {
        return std::vector<DataAccess>{{static_cast<std::uint16_t>(address), write}};
    };
    // LDD/STD Rd, Y+q / Z+q (LD/ST through Y or Z without change are q = 0):
    // 10q0 qqsd dddd yqqq, s = store, y = Y (else Z).
    if ((opcode & 0xD000) == 0x8000) {
        const unsigned q = ((opcode >> 8) & 0x20) | ((opcode >> 7) & 0x18) | (opcode & 0x07);
        const unsigned base = (opcode & 0x0008) != 0 ? kY : kZ;
        return at(pair_at(data, base) + q, (opcode & 0x0200) != 0);
    }
    // IN Rd, A: 1011 0AAd dddd AAAA; OUT A, Rr: 1011 1AAr rrrr AAAA.
    if ((opcode & 0xF000) == 0xB000) {
        const unsigned a = ((opcode >> 5) & 0x30) | (opcode & 0x0F);
        return at(0x20 + a, (opcode & 0x0800) != 0);
    }
    // CBI/SBIC/SBI/SBIS A, b: 1001 10xx AAAA Abbb (xx: 00 CBI, 01 SBIC, 10 SBI, 11 SBIS).
    if ((opcode & 0xFC00) == 0x9800) {
        const unsigned a = 0x20 + ((opcode >> 3) & 0x1F);
        const unsigned op = (opcode >> 8) & 0x3;
        if (op == 0 || op == 2) return {{static_cast<std::uint16_t>(a), false}, {static_cast<std::uint16_t>(a), true}};
        return at(a, false);
    }
    // 1001 00sd dddd xxxx: LDS/STS, LD/ST with X, Y+/-Y, Z+/-Z, PUSH/POP.
    if ((opcode & 0xFC00) == 0x9000) {
        const bool store = (opcode & 0x0200) != 0;
        switch (opcode & 0x000F) {
            case 0x0: return at(next, store);                      // LDS/STS k
            case 0x1: return at(pair_at(data, kZ), store);         // Z+
            case 0x2: return at(pair_at(data, kZ) - 1u, store);    // -Z
            case 0x9: return at(pair_at(data, kY), store);         // Y+
            case 0xA: return at(pair_at(data, kY) - 1u, store);    // -Y
            case 0xC: return at(pair_at(data, kX), store);         // X
            case 0xD: return at(pair_at(data, kX), store);         // X+
            case 0xE: return at(pair_at(data, kX) - 1u, store);    // -X
            case 0xF:                                              // PUSH writes at SP, POP reads SP+1
                return store ? at(pair_at(data, kSpl), true) : at(pair_at(data, kSpl) + 1u, false);
            default: break;  // LPM/ELPM (program memory), XCH/LAS/LAC/LAT (XMEGA only)
        }
    }
    return {};
}

}  // namespace avrbench
