// mcu/BlockTranslator: straight runs of instructions run as host code
// inside PredecodedCore::run_batch, with the same effect, cycles and
// instruction count as the interpreter's handlers - and the interpreter
// taking over in front of whatever the block cannot do itself. Programs
// written into flash by hand (opcodes from the AVR Instruction Set
// Manual; expected values worked out by hand next to each), run on one
// core with translation and one without. The exhaustive checks are
// elsewhere: core_sweep's every operand pair and the workload suite
// against simavr (test_predecoded_core.cpp, test_workloads.cpp) and every
// firmware against the reference loop (test_run_loop.cpp), all on this
// core with translation on; the first test here proves they run blocks
// holding every kind a block can hold.
#include <gtest/gtest.h>

#include <cstring>
#include <initializer_list>
#include <string>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/BlockTranslator.hpp"
#include "mcu/ElfImage.hpp"
#include "mcu/Mcu.hpp"
#include "mcu/PredecodedCore.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

std::uint16_t ldi(unsigned d, unsigned k) { return static_cast<std::uint16_t>(0xE000 | ((k & 0xF0) << 4) | ((d - 16) << 4) | (k & 0x0F)); }
std::uint16_t two_regs(std::uint16_t base, unsigned d, unsigned r) {
    return static_cast<std::uint16_t>(base | ((r & 0x10) << 5) | (d << 4) | (r & 0x0F));
}
std::uint16_t add(unsigned d, unsigned r) { return two_regs(0x0C00, d, r); }
std::uint16_t adc(unsigned d, unsigned r) { return two_regs(0x1C00, d, r); }
std::uint16_t sub(unsigned d, unsigned r) { return two_regs(0x1800, d, r); }
std::uint16_t ld_x(unsigned d) { return static_cast<std::uint16_t>(0x900C | (d << 4)); }   // LD Rd, X
std::uint16_t push(unsigned r) { return static_cast<std::uint16_t>(0x920F | (r << 4)); }  // PUSH Rr
std::uint16_t rcall(int words) { return static_cast<std::uint16_t>(0xD000 | (words & 0x0FFF)); }
constexpr std::uint16_t kRet = 0x9508, kWdr = 0x95A8;

// A scratch page far from busy_poll's code, on a core with or without
// translation; run() runs one batch from it up to the WDR (which
// avr_run_one executes, so the batch hands over in front of it).
struct Scratch {
    static constexpr avr_flashaddr_t kAt = 0x1000;
    ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu{elf, McuOptions{}};
    avr_t* avr = mcu.avr();
    PredecodedCore core;
    explicit Scratch(bool translate) : core(avr, avr->flashend - 1, ~0u, translate) {}
    void write(avr_flashaddr_t at, std::initializer_list<std::uint16_t> words) {
        for (std::uint16_t w : words) {
            avr->flash[at] = static_cast<std::uint8_t>(w);
            avr->flash[at + 1] = static_cast<std::uint8_t>(w >> 8);
            at += 2;
        }
    }
    PredecodedCore::Batch run(std::uint16_t stack_floor = 0) {
        avr->pc = kAt;
        const PredecodedCore::BatchLimits limits{avr->cycle + 1'000'000, 1000, static_cast<std::uint32_t>(avr->flashend - 1), ~0u,
                                                 stack_floor};
        return core.run_batch<false>(avr, limits, nullptr);
    }
    std::uint16_t sp() const { return static_cast<std::uint16_t>(avr->data[R_SPL] | (avr->data[R_SPH] << 8)); }
    void set_sp(std::uint16_t sp) {
        avr->data[R_SPL] = static_cast<std::uint8_t>(sp);
        avr->data[R_SPH] = static_cast<std::uint8_t>(sp >> 8);
    }
};

TEST(BlockTranslator, TheBatchedTestsRunBlocksHoldingEveryKindABlockCanHold) {
    if (!BlockTranslator::available()) GTEST_SKIP() << "no block translation on this host";
    std::uint64_t ops = 0;
    for (const std::string name : {"core_sweep", "workload_1", "workload_2", "workload_3", "workload_4", "workload_5", "workload_6",
                                   "workload_7", "workload_8", "workload_9"}) {
        Mcu mcu(ElfImage::load(test::firmware(name)), McuOptions{});
        // core_sweep ends within 12 M cycles, each workload within 160 M.
        while (mcu.run_until(mcu.cycle() + mcu.frequency_hz()) != StopReason::Halted && mcu.cycle() < 320'000'000) {
        }
        ASSERT_TRUE(mcu.halted()) << name;
        EXPECT_GT(mcu.predecoded_core()->translated_blocks(), 0u) << name;
        ops |= mcu.predecoded_core()->translated_ops();
    }
    for (unsigned op = 0; op <= static_cast<unsigned>(BlockTranslator::Op::kIcall); ++op) {
        EXPECT_TRUE(ops & (std::uint64_t{1} << op)) << "no block held BlockTranslator::Op " << op;
    }
}

// LDI r16, 0x12; LDI r17, 0x3C; ADD r16, r17; ADC r17, r16; WDR.
// By hand: r16 = 0x12 + 0x3C = 0x4E (no carry out of bit 3: 2 + 12 < 16);
// r17 = 0x3C + 0x4E + C 0 = 0x8A: H set (12 + 14 = 26 carries out of
// bit 3), N set, V set (two positive operands, a negative sum), S = N ^ V
// clear, C and Z clear. Four instructions of one cycle each.
TEST(BlockTranslator, ABlockDoesWhatItsInstructionsDoOneByOne) {
    if (!BlockTranslator::available()) GTEST_SKIP() << "no block translation on this host";
    for (bool translate : {true, false}) {
        Scratch s(translate);
        s.write(Scratch::kAt, {ldi(16, 0x12), ldi(17, 0x3C), add(16, 17), adc(17, 16), kWdr});
        const Cycle before = s.avr->cycle;
        const PredecodedCore::Batch b = s.run();
        EXPECT_EQ(b.ended, PredecodedCore::Ended::HandOver);
        EXPECT_EQ(b.steps, 4u);
        EXPECT_EQ(s.avr->cycle - before, 4u);
        EXPECT_EQ(s.avr->pc, Scratch::kAt + 8);
        EXPECT_EQ(s.avr->data[16], 0x4E);
        EXPECT_EQ(s.avr->data[17], 0x8A);
        const std::uint8_t expected_sreg[6] = {0, 0, 1, 1, 0, 1};  // C Z N V S H
        EXPECT_EQ(0, std::memcmp(s.avr->sreg, expected_sreg, 6)) << (translate ? "translated" : "interpreted");
        EXPECT_EQ(s.core.translated_blocks(), translate ? 1u : 0u);
    }
}

// A load from outside plain RAM - here GPIOR0 (I/O 0x1E, data address
// 0x3E on the ATmega328P; no callback, so the interpreter reads it in the
// batch) - is not the block's to make: it stops in front of it and the
// interpreter runs it, in the middle of a block (the charge of the two
// LDIs before it kept) and at its start (the block runs nothing).
// LDI r26, 0x3E; LDI r27, 0; LD r16, X; LDI r17, 1; WDR: 1 + 1 + 2 + 1
// cycles. Then LD r18, X; LDI r19, 2; WDR with X still 0x3E: 2 + 1.
TEST(BlockTranslator, TheInterpreterRunsAnAccessABlockCannotMake) {
    if (!BlockTranslator::available()) GTEST_SKIP() << "no block translation on this host";
    Scratch s(true);
    s.avr->data[0x3E] = 0x5A;
    s.write(Scratch::kAt, {ldi(26, 0x3E), ldi(27, 0), ld_x(16), ldi(17, 1), kWdr});
    Cycle before = s.avr->cycle;
    PredecodedCore::Batch b = s.run();
    EXPECT_EQ(b.ended, PredecodedCore::Ended::HandOver);
    EXPECT_EQ(b.steps, 4u);
    EXPECT_EQ(s.avr->cycle - before, 5u);
    EXPECT_EQ(s.avr->pc, Scratch::kAt + 8);
    EXPECT_EQ(s.avr->data[16], 0x5A);
    EXPECT_EQ(s.avr->data[17], 1);
    EXPECT_EQ(s.core.translated_blocks(), 1u);
    s.write(Scratch::kAt, {ld_x(18), ldi(19, 2), kWdr});
    s.core.flash_written(Scratch::kAt, Scratch::kAt + 6);
    before = s.avr->cycle;
    b = s.run();
    EXPECT_EQ(b.steps, 2u);
    EXPECT_EQ(s.avr->cycle - before, 3u);
    EXPECT_EQ(s.avr->data[18], 0x5A);
    EXPECT_EQ(s.avr->data[19], 2);
    EXPECT_EQ(s.core.translated_blocks(), 2u) << "LD r18, X; LDI r19, 2 made a block, which ran nothing";
}

// The crash oracle's stack floor: SP below it after an instruction ends the
// batch there (Ended::CheckPc) for Mcu to judge. With the floor at 0x800
// and SP at 0x801: LDI r16, 5; PUSH r16 (SP 0x800, at the floor); PUSH r16
// (SP 0x7FF, below it); WDR. The block stops in front of the second PUSH,
// which the interpreter runs and reports.
TEST(BlockTranslator, APushPastTheStackFloorIsLeftToTheOracle) {
    if (!BlockTranslator::available()) GTEST_SKIP() << "no block translation on this host";
    for (bool translate : {true, false}) {
        Scratch s(translate);
        s.set_sp(0x801);
        s.write(Scratch::kAt, {ldi(16, 5), push(16), push(16), kWdr});
        const PredecodedCore::Batch b = s.run(0x800);
        EXPECT_EQ(b.ended, PredecodedCore::Ended::CheckPc);
        EXPECT_EQ(s.avr->pc, Scratch::kAt + 4) << "the second PUSH";
        EXPECT_EQ(b.new_pc, Scratch::kAt + 6);
        EXPECT_EQ(s.sp(), 0x7FF);
        EXPECT_EQ(s.avr->data[0x801], 5);
        EXPECT_EQ(s.avr->data[0x800], 5);
    }
}

// A call and a return in blocks. LDI r17, 1; RCALL f (+1 word); WDR;
// f: LDI r16, 7; RET. RCALL pushes the return address in words
// ((0x1000 + 4) / 2 = 0x802: low byte 0x02 at SP, high 0x08 below, as
// _avr_push_addr), RET pops it. Cycles by hand (ATmega328P, 2-byte return
// addresses): LDI 1, RCALL 3, LDI 1, RET 4.
TEST(BlockTranslator, ACallAndItsReturnRunInBlocks) {
    if (!BlockTranslator::available()) GTEST_SKIP() << "no block translation on this host";
    for (bool translate : {true, false}) {
        Scratch s(translate);
        s.set_sp(0x8FF);
        s.write(Scratch::kAt, {ldi(17, 1), rcall(1), kWdr, ldi(16, 7), kRet});
        const Cycle before = s.avr->cycle;
        const PredecodedCore::Batch b = s.run();
        EXPECT_EQ(b.ended, PredecodedCore::Ended::HandOver);
        EXPECT_EQ(s.avr->pc, Scratch::kAt + 4) << "at the WDR after the call";
        EXPECT_EQ(b.steps, 4u);
        EXPECT_EQ(s.avr->cycle - before, 9u);
        EXPECT_EQ(s.sp(), 0x8FF);
        EXPECT_EQ(s.avr->data[0x8FF], 0x02);
        EXPECT_EQ(s.avr->data[0x8FE], 0x08);
        EXPECT_EQ(s.avr->data[16], 7);
        EXPECT_EQ(s.core.translated_blocks() > 0, translate);
    }
}

// A flash write inside a block whose first instruction it does not touch
// (a debugger's, announced through flash_written): the block is no longer
// entered, so the new instruction runs. LDI r16, 1; LDI r17, 2; ADD r16,
// r17; WDR gives r16 = 3; with the ADD rewritten to SUB r16, r17 it gives
// 1 - 2 = 0xFF.
TEST(BlockTranslator, AFlashWriteInsideABlockIsRunAsWritten) {
    if (!BlockTranslator::available()) GTEST_SKIP() << "no block translation on this host";
    Scratch s(true);
    s.write(Scratch::kAt, {ldi(16, 1), ldi(17, 2), add(16, 17), kWdr});
    s.run();
    EXPECT_EQ(s.avr->data[16], 3);
    ASSERT_EQ(s.core.translated_blocks(), 1u);
    s.write(Scratch::kAt + 4, {sub(16, 17)});
    s.core.flash_written(Scratch::kAt + 4, Scratch::kAt + 6);
    s.run();
    EXPECT_EQ(s.avr->data[16], 0xFF);
}

}  // namespace
}  // namespace avrbench
