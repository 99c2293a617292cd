// Straight runs of AVR instructions translated into host (x86-64) code,
// for PredecodedCore::run_batch: a block is one call where the threaded
// interpreter paid a dispatch, a fuel test and a handler per instruction
// (docs/PERFORMANCE.md, "Translated blocks").
//
// A block holds instructions that call nothing in simavr: ALU operations,
// register moves, LDI, MUL, ADIW, SBIW, BST/BLD, the flag sets and clears
// other than I, loads and stores of plain RAM, PUSH/POP, LPM; it may end
// in a branch, RJMP, a call or a return. So no timer, IRQ or interrupt can
// change inside it, and run_batch enters it only when the fuel covers all
// of it (the cycle limit and the step limit): the batch ends where it
// would have one instruction at a time. Whatever an instruction cannot do
// there at run time (an access that is not plain RAM, the stack at the
// crash oracle's floor, a new PC at the oracles' limits, Z past the flash)
// the code leaves to the interpreter: it returns in front of it, with
// every flag in SREG.
//
// Each instruction does what the predecoded core's handler does
// (PredecodedOps.inc, simavr 1.6's avr_run_one), flags included: from the
// host's own flags (as the handlers' add8/sub8) through tables built from
// the handlers' formulas. A flag that a later instruction of the same block
// sets again before anything reads it is not computed; C and Z that only
// the next instruction reads, from the host's registers, are not stored.
// Proven against the interpreter and avr_run_one by the batched-run tests
// (core_sweep's every operand pair, every firmware, the workload suite)
// and tests/core/test_block_translator.cpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {

class BlockTranslator {
public:
    // The instructions a block may hold (PredecodedCore's kinds, named here
    // so this file does not depend on their numbering).
    enum class Op : std::uint8_t {
        kNop, kAdd, kAdc, kSub, kSbc, kCp, kCpc, kCpi, kSubi, kSbci, kAnd, kOr, kEor, kAndi, kOri,
        kMov, kMovw, kLdi, kInc, kDec, kCom, kNeg, kSwap, kLsr, kAsr, kRor, kMul, kAdiw, kSbiw,
        kBst, kBld, kSregSet, kSregClear,
        // Data memory and flash: where an access is not plain RAM (or the
        // stack would pass the crash oracle's floor, or Z past the flash),
        // the block ends in front of the instruction and the interpreter
        // runs it.
        kLdX, kLdY, kLdZ, kStX, kStY, kStZ,  // b: 0 plain, 1 post-increment, 2 pre-decrement
        kLddY, kLddZ, kStdY, kStdZ,          // b: the displacement q
        kLds, kSts,                          // two words; `address` the data address
        kLpm, kLpmInc, kPush, kPop,
        // May only end a block. CALL's `target` is its (static) target;
        // RET, IJMP and ICALL stop in front of themselves where their new
        // PC is at the crash oracles' limits.
        kBrbs, kBrbc, kRjmp, kRcall, kCall, kRet, kIjmp, kIcall,
    };
    struct Instruction {
        Op op;
        std::uint8_t a;          // Rd (the low register of a pair), or the SREG bit of a flag set/clear
        std::uint8_t b;          // Rr, K, the bit number (branches: the SREG bit), the X/Y/Z mode, q
        std::uint32_t target;    // branches and RJMP: the new PC in bytes; LDS/STS: the data address
    };
    // What the translated code may take as plain data memory and the crash
    // oracles' stack floor, fixed when it is translated (PredecodedCore
    // translates again when the floor changes).
    struct Memory {
        std::uint16_t ram_begin;    // data addresses [ram_begin, ramend] are plain RAM
        std::uint16_t ramend;
        std::uint16_t stack_floor;  // SP below it after an instruction: the oracle's
        bool stack_plain;           // SPL and SPH have no callbacks or IRQs
        avr_flashaddr_t flashend;
        const std::uint8_t* flash;
        int address_size;                    // bytes of a return address (2, or 3 past 128 KiB of flash)
        std::uint32_t code_end_minus_one;    // the PC oracles (PredecodedCore::BatchLimits)
        std::uint32_t bad_interrupt_pc;
    };
    // The code's answer: where the dispatch goes on (the block's end, a
    // branch's target, or an instruction the interpreter must run), and the
    // meter charge of the instructions it ran (PredecodedCore::run_batch:
    // cycles << step_bits, plus one per instruction). A charge of 0: it ran
    // none (the first needs the interpreter).
    struct Exit {
        std::uint64_t pc;
        std::uint64_t charge;
    };
    using Code = Exit (*)(std::uint8_t* data, std::uint8_t* sreg);
    struct Block {
        Code code;
        std::int64_t max_charge;  // every instruction, a branch at the end taken
        avr_flashaddr_t head;     // the first instruction's PC
        avr_flashaddr_t end;      // the PC after the last
    };

    // Host code translation exists on this host (x86-64 with GCC or clang).
    static bool available();
    // The cycles an Op takes (a branch: not taken) and its words.
    static int cycles_of(Op op, int address_size);
    static int words_of(Op op) { return op == Op::kLds || op == Op::kSts || op == Op::kCall ? 2 : 1; }
    static bool ends_block(Op op) { return op >= Op::kBrbs; }

    BlockTranslator();
    ~BlockTranslator();
    BlockTranslator(const BlockTranslator&) = delete;
    BlockTranslator& operator=(const BlockTranslator&) = delete;

    // Translates `count` instructions from `head`; the index of the new
    // block, or -1 when the code memory is full or could not be had (then
    // the interpreter runs them, as before). step_bits: the meter's layout.
    int translate(const Instruction* instructions, std::size_t count, avr_flashaddr_t head, const Memory& memory, int step_bits);
    const Block& block(std::size_t index) const { return blocks_[index]; }
    const Block* block_array() const { return blocks_.data(); }
    std::size_t blocks() const { return blocks_.size(); }
    // Bit n set: some block held Op n (for the tests' coverage check).
    std::uint64_t ops_translated() const { return ops_translated_; }
    // Forgets every block (the slots that pointed at them were decoded
    // again). Their code memory is not written again: a tool that caches
    // translated host code (valgrind) would otherwise run the old code.
    void forget_all() { blocks_.clear(); }

private:
    std::uint8_t* code_ = nullptr;   // mmap'd, read-write-execute
    std::size_t code_bytes_ = 0;
    std::size_t code_used_ = 0;
    std::vector<Block> blocks_;
    std::uint64_t ops_translated_ = 0;
};

}  // namespace avrbench
