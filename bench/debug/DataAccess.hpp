// Which data-space bytes an AVR instruction reads or writes, worked out in
// front of it from its opcode and the pointer registers: what a watchpoint
// needs to stop at the exact instruction. Covers the instructions that
// address data memory on the ATmega cores (LD/LDD/LDS, ST/STD/STS, PUSH/POP,
// IN/OUT, SBI/CBI, SBIC/SBIS); the stack traffic of CALL/RET and interrupts
// is not a watched variable's and is left out.
// Source: Microchip "AVR Instruction Set Manual" (DS40002198), the opcode
// tables of each instruction.
#pragma once

#include <cstdint>
#include <vector>

namespace avrbench {

struct DataAccess {
    std::uint16_t address;  // data space (registers at 0x00, I/O at 0x20)
    bool write;
};

// `opcode` and `next` are the instruction's words; `data` the data space now
// (registers X/Y/Z and SP are read from it, SP at 0x5D/0x5E).
std::vector<DataAccess> data_accesses(std::uint16_t opcode, std::uint16_t next, const std::uint8_t* data);

}  // namespace avrbench
