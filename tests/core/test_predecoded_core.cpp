// mcu/PredecodedCore against simavr's avr_run_one, instruction by
// instruction: every firmware the build makes runs on two MCUs, one on each
// core, with the same serial input, and after every instruction the two
// must agree on the cycle, PC, core state, interrupt state, all eight SREG
// flags, the 32 registers and SP; every 64 instructions and at the end on
// all of data memory (registers, I/O, RAM). Anything the predecoded core
// does not execute itself it hands to avr_run_one, so the test also counts
// what it did execute: nearly all instructions, and every kind of
// instruction it has, somewhere in the firmware set (core_sweep exists to
// reach the kinds compiled C rarely emits, over all operand pairs).
#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <set>
#include <string>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "mcu/PredecodedCore.hpp"
#include "support/EveryFirmware.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

// Writes one opcode word into flash at byte address `at` (little-endian).
void put_word(avr_t* avr, avr_flashaddr_t at, std::uint16_t word) {
    avr->flash[at] = static_cast<std::uint8_t>(word);
    avr->flash[at + 1] = static_cast<std::uint8_t>(word >> 8);
}

struct Compared {
    std::uint64_t instructions = 0;
    std::uint64_t handed = 0;
    std::set<int> kinds;
};

// Runs `name` on both cores for up to `max_steps` instructions; the first
// difference fails the test with the instruction's PC and cycle.
void run_both(const std::string& name, std::uint64_t max_steps, Compared& out) {
    const ElfImage elf = ElfImage::load(test::firmware(name));
    McuOptions simavr_options, predecoded_options;
    simavr_options.predecoded_core = false;
    simavr_options.skip_idle_loops = predecoded_options.skip_idle_loops = false;
    test::set_board_mcu(name, elf, simavr_options);
    test::set_board_mcu(name, elf, predecoded_options);
    Mcu ref(elf, simavr_options), fast(elf, predecoded_options);
    ASSERT_EQ(ref.predecoded_core(), nullptr);
    ASSERT_NE(fast.predecoded_core(), nullptr);
    for (Mcu* m : {&ref, &fast}) {
        try {
            m->uart(0).send("G1 X1\n?\nM105\nhello\n");
        } catch (const BadInput&) {
            // an MCU without USART0
        }
    }
    const avr_t* a = ref.avr();
    const avr_t* b = fast.avr();
    const std::size_t data_size = static_cast<std::size_t>(a->ramend) + 1;
    std::uint64_t step = 0;
    for (; step < max_steps; ++step) {
        const avr_flashaddr_t pc = a->pc;
        const Cycle cycle = a->cycle;
        if (a->state == cpu_Running && pc < a->flashend) {
            const std::uint16_t word = static_cast<std::uint16_t>(a->flash[pc] | (a->flash[pc + 1] << 8));
            out.kinds.insert(PredecodedCore::decode(a, word, pc).kind);
        }
        const bool ref_alive = ref.step();
        const bool fast_alive = fast.step();
        const auto where = [&] {
            return name + ": instruction " + std::to_string(step) + " at PC 0x" + [&] {
                char hex[16];
                std::snprintf(hex, sizeof hex, "%04x", pc);
                return std::string(hex);
            }() + ", cycle " + std::to_string(cycle);
        };
        ASSERT_EQ(ref_alive, fast_alive) << where();
        ASSERT_EQ(a->cycle, b->cycle) << where();
        ASSERT_EQ(a->pc, b->pc) << where();
        ASSERT_EQ(a->state, b->state) << where();
        ASSERT_EQ(a->interrupt_state, b->interrupt_state) << where();
        ASSERT_EQ(0, std::memcmp(a->sreg, b->sreg, sizeof a->sreg)) << where() << ": SREG differs";
        ASSERT_EQ(0, std::memcmp(a->data, b->data, 32)) << where() << ": registers differ";
        ASSERT_EQ(a->data[R_SPL], b->data[R_SPL]) << where();
        ASSERT_EQ(a->data[R_SPH], b->data[R_SPH]) << where();
        if ((step & 63) == 0) {
            ASSERT_EQ(0, std::memcmp(a->data, b->data, data_size)) << where() << ": data memory differs";
        }
        if (!ref_alive) break;
    }
    ASSERT_EQ(0, std::memcmp(a->data, b->data, data_size)) << name << ": data memory differs at the end";
    EXPECT_EQ(ref.findings().size(), fast.findings().size()) << name;
    out.instructions += step;
    out.handed += fast.predecoded_core()->handed_to_simavr();
}

TEST(PredecodedCore, MatchesAvrRunOneInstructionByInstructionOnEveryFirmware) {
    const auto names = test::all_firmware();
    ASSERT_GT(names.size(), 100u);  // the build's whole firmware set
    Compared total;
    for (const auto& name : names) {
        // 200 000 instructions: past every firmware's start-up (clearing
        // .bss, copying .data, setting up peripherals) into its main loop
        // and its first interrupts; core_sweep to its end.
        run_both(name, name == "core_sweep" ? 100'000'000 : 200'000, total);
        if (::testing::Test::HasFatalFailure()) return;
    }
    // The predecoded core executed most instructions itself (the rest are
    // I/O with callbacks, SEI/CLI/RETI, SLEEP...), so the comparison
    // compared it, not avr_run_one with itself.
    EXPECT_LT(total.handed * 4, total.instructions) << total.handed << " of " << total.instructions << " handed to avr_run_one";
    // Every kind the core executes itself ran somewhere.
    for (int kind = PredecodedCore::kNop; kind < PredecodedCore::kKinds; ++kind) {
        if (kind == PredecodedCore::kBlock) continue;  // a handler only, never a slot's kind
        EXPECT_TRUE(total.kinds.count(kind)) << "no firmware executed predecoded kind " << kind;
    }
}

// The batched fast path (PredecodedCore::run_batch inside Mcu::run_until)
// against the reference loop (avr_run_one, every timer processed on every
// step) over all of core_sweep: RunLoop.* cover every firmware for 20 ms,
// which is a fraction of the sweep. Both end halted at the same cycle with
// the same registers, SREG and RAM.
TEST(PredecodedCore, BatchedRunEndsWhereTheReferenceLoopEndsOnCoreSweep) {
    const ElfImage elf = ElfImage::load(test::firmware("core_sweep"));
    McuOptions reference_options;
    reference_options.reference_run_loop = true;
    Mcu fast(elf, McuOptions{}), reference(elf, reference_options);
    ASSERT_NE(fast.predecoded_core(), nullptr);
    // 2 s of simulated time; the sweep ends after ~0.75 s (11.9 M cycles at 16 MHz).
    const Cycle limit = 32'000'000;
    EXPECT_EQ(fast.run_until(limit), StopReason::Halted);
    EXPECT_EQ(reference.run_until(limit), StopReason::Halted);
    const avr_t* a = reference.avr();
    const avr_t* b = fast.avr();
    EXPECT_EQ(a->cycle, b->cycle);
    EXPECT_EQ(a->pc, b->pc);
    EXPECT_EQ(0, std::memcmp(a->sreg, b->sreg, sizeof a->sreg));
    EXPECT_TRUE(reference.data_memory() == fast.data_memory());
    EXPECT_EQ(reference.steps(), fast.steps());
    // The batches ran nearly all of it: the sweep has no I/O but its end.
    EXPECT_LT(fast.predecoded_core()->handed_to_simavr(), 1000u);
}

// A flash word that changes under a decoded slot (a boot loader or SPM
// rewriting the application, a debugger) is decoded again: the slot keeps
// the word it was decoded from. Here the firmware's flash is patched
// between two runs of the same instruction: LDI r16, 0x12 becomes
// LDI r16, 0x34 (opcodes from the AVR instruction set manual:
// 1110 KKKK dddd KKKK, d = 16 + dddd).
TEST(PredecodedCore, DecodesAgainWhenTheFlashWordChanges) {
    const ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu(elf, McuOptions{});
    avr_t* avr = mcu.avr();
    PredecodedCore core(avr);
    // A scratch location at the end of flash, far from the program.
    const avr_flashaddr_t at = (avr->flashend + 1) - 64;
    const auto put = [&](std::uint16_t word) { put_word(avr, at, word); };
    avr->pc = at;
    put(0xe102);  // LDI r16, 0x12
    EXPECT_EQ(core.run_one(avr), at + 2);
    EXPECT_EQ(avr->data[16], 0x12);
    put(0xe304);  // LDI r16, 0x34
    const Cycle before = avr->cycle;
    EXPECT_EQ(core.run_one(avr), at + 2);
    EXPECT_EQ(avr->data[16], 0x34);
    EXPECT_EQ(avr->cycle, before + 1);  // LDI: 1 cycle
    EXPECT_EQ(core.handed_to_simavr(), 0u);
}

// LDS and STS keep the address word they were decoded with (the batch's
// fast path, and whether an STS may move SP, come from it): flash holding
// another address there is noticed. Opcodes from the AVR instruction set
// manual: STS k, Rr = 1001 001d dddd 0000 + k; LDS Rd, k = 1001 000d dddd
// 0000 + k; LDI Rd, K = 1110 KKKK dddd KKKK (d = 16 + dddd).
TEST(PredecodedCore, LdsAndStsFollowTheirAddressWordWhenFlashChangesIt) {
    const ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu(elf, McuOptions{});
    avr_t* avr = mcu.avr();
    PredecodedCore core(avr);
    const avr_flashaddr_t at = (avr->flashend + 1) - 64;
    const auto put = [&](avr_flashaddr_t where, std::uint16_t word) { put_word(avr, where, word); };
    const std::uint16_t first = 0x0300, second = 0x0301;  // SRAM on the ATmega328P (0x0100..0x08FF)
    put(at, 0x9300);  // STS k, r16
    put(at + 2, first);
    avr->data[16] = 0x5a;
    avr->pc = at;
    EXPECT_EQ(core.run_one(avr), at + 4);
    EXPECT_EQ(avr->data[first], 0x5a);
    put(at + 2, second);
    avr->data[16] = 0xa5;
    EXPECT_EQ(core.run_one(avr), at + 4);
    EXPECT_EQ(avr->data[second], 0xa5);
    EXPECT_EQ(avr->data[first], 0x5a);

    put(at, 0x9110);  // LDS r17, k
    put(at + 2, first);
    EXPECT_EQ(core.run_one(avr), at + 4);
    EXPECT_EQ(avr->data[17], 0x5a);
    put(at + 2, second);
    EXPECT_EQ(core.run_one(avr), at + 4);
    EXPECT_EQ(avr->data[17], 0xa5);
}

// run_batch does not compare a slot with flash on every fetch: what writes
// flash invalidates the slots there. An SPM (simavr's flash module, through
// avr_ioctl) and a debugger's write (Mcu::flash_written) both must. Here a
// batch runs LDI r16, 0x12 at an application page and stops at WDR (an
// instruction avr_run_one executes); the boot section's OUT SPMCSR, r20;
// SPM then rewrite the page (fill the temporary page word by word with
// SPMEN, erase with PGERS|SPMEN, write with PGWRT|SPMEN: ATmega328P
// datasheet, "Self-Programming the Flash"; SPMCSR is I/O 0x37, bits SPMEN
// 0, PGERS 1, PGWRT 2) to LDI r16, 0x34; WDR, and the batch must run that.
// Opcodes (AVR instruction set manual): LDI Rd, K = 1110 KKKK dddd KKKK;
// OUT A, Rr = 1011 1AAr rrrr AAAA; SPM = 0x95E8; WDR = 0x95A8.
TEST(PredecodedCore, BatchRunsWhatAnSpmWroteOverDecodedCode) {
    const ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu(elf, McuOptions{});
    avr_t* avr = mcu.avr();
    PredecodedCore core(avr, avr->flashend - 1);
    const avr_flashaddr_t page = 0x1000;  // 128-byte pages on the ATmega328P
    // The last 512 bytes lie in the boot section whatever BOOTSZ says
    // (256 words at least): only SPM from there writes (fixes/SelfProgramming).
    const avr_flashaddr_t boot = (avr->flashend + 1) - 256;
    constexpr std::uint16_t kWdr = 0x95A8;
    const auto ldi_r16 = [](std::uint8_t k) { return static_cast<std::uint16_t>(0xE000 | ((k & 0xF0) << 4) | (k & 0x0F)); };
    put_word(avr, page, ldi_r16(0x12));
    put_word(avr, page + 2, kWdr);
    put_word(avr, boot, 0xBF47);  // OUT 0x37 (SPMCSR), r20: 0xB800 | (0x30 << 5) | (20 << 4) | 0x7
    put_word(avr, boot + 2, 0x95E8);
    const auto run_page = [&] {
        avr->pc = page;
        const PredecodedCore::BatchLimits limits{avr->cycle + 1'000'000, 100, static_cast<std::uint32_t>(avr->flashend - 1), ~0u, 0};
        return core.run_batch<false>(avr, limits, nullptr);
    };
    PredecodedCore::Batch b = run_page();
    EXPECT_EQ(b.ended, PredecodedCore::Ended::HandOver);
    EXPECT_EQ(avr->pc, page + 2);
    EXPECT_EQ(avr->data[16], 0x12);

    const auto spm = [&](std::uint8_t spmcsr, avr_flashaddr_t z, std::uint16_t r1_r0) {
        avr->data[20] = spmcsr;
        avr->data[R_ZL] = static_cast<std::uint8_t>(z);
        avr->data[R_ZH] = static_cast<std::uint8_t>(z >> 8);
        avr->data[0] = static_cast<std::uint8_t>(r1_r0);
        avr->data[1] = static_cast<std::uint8_t>(r1_r0 >> 8);
        avr->pc = boot;
        avr->pc = core.run_one(avr);  // OUT
        avr->pc = core.run_one(avr);  // SPM (avr_run_one's)
        ASSERT_EQ(avr->pc, boot + 4);
    };
    spm(0x01, page, ldi_r16(0x34));
    spm(0x01, page + 2, kWdr);
    spm(0x03, page, 0);
    spm(0x05, page, 0);
    ASSERT_EQ(avr->flash[page] | (avr->flash[page + 1] << 8), ldi_r16(0x34)) << "the SPMs wrote the page";

    b = run_page();
    EXPECT_EQ(b.ended, PredecodedCore::Ended::HandOver);
    EXPECT_EQ(avr->data[16], 0x34) << "the batch ran the slot decoded before the SPM";

    // A write from outside (a debugger's), announced.
    put_word(avr, page, ldi_r16(0x56));
    core.flash_written(page, page + 2);
    b = run_page();
    EXPECT_EQ(avr->data[16], 0x56);
}

// An STS keeps its address word in the slot: a write of that word alone
// (the slot's second) makes the slot decode again too.
TEST(PredecodedCore, BatchFollowsAWriteOfAnStsAddressWord) {
    const ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu(elf, McuOptions{});
    avr_t* avr = mcu.avr();
    PredecodedCore core(avr, avr->flashend - 1);
    const avr_flashaddr_t at = 0x1000;
    put_word(avr, at, 0x9300);  // STS k, r16: 1001 001d dddd 0000, k in the next word
    put_word(avr, at + 2, 0x0300);
    put_word(avr, at + 4, 0x95A8);  // WDR
    const auto run = [&] {
        avr->pc = at;
        const PredecodedCore::BatchLimits limits{avr->cycle + 1'000'000, 100, static_cast<std::uint32_t>(avr->flashend - 1), ~0u, 0};
        return core.run_batch<false>(avr, limits, nullptr);
    };
    avr->data[16] = 0x5a;
    run();
    EXPECT_EQ(avr->data[0x0300], 0x5a);
    put_word(avr, at + 2, 0x0301);
    core.flash_written(at + 2, at + 4);
    avr->data[16] = 0xa5;
    run();
    EXPECT_EQ(avr->data[0x0301], 0xa5);
    EXPECT_EQ(avr->data[0x0300], 0x5a);
}

// run_batch tests the crash oracles only after the slots whose `check`
// says they can trip them, computed for the limits the core was given; a
// batch with other limits (a boot loader that wrote another application)
// decodes every slot again. Here a loop of NOP, NOP, RJMP back (RJMP k =
// 1100 kkkk kkkk kkkk, k = -3 words: 0xCFFD) with __bad_interrupt placed
// at each of its instructions in turn: the batch must stop in front of it.
TEST(PredecodedCore, BatchStopsWhereTheOraclesLimitsSayEvenWhenTheyChange) {
    const ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu(elf, McuOptions{});
    avr_t* avr = mcu.avr();
    const avr_flashaddr_t at = (avr->flashend + 1) - 64;
    const auto put = [&](avr_flashaddr_t where, std::uint16_t word) { put_word(avr, where, word); };
    put(at, 0x0000);
    put(at + 2, 0x0000);
    put(at + 4, 0xcffd);
    const std::uint32_t code_end_minus_one = avr->flashend - 1;  // the loop is inside the code
    PredecodedCore core(avr, code_end_minus_one, at + 2);
    const auto batch = [&](std::uint32_t bad_interrupt_pc) {
        avr->pc = at;
        const PredecodedCore::BatchLimits limits{avr->cycle + 1'000'000, 100, code_end_minus_one, bad_interrupt_pc, 0};
        return core.run_batch<false>(avr, limits, nullptr);
    };
    PredecodedCore::Batch b = batch(at + 2);
    EXPECT_EQ(b.ended, PredecodedCore::Ended::CheckPc);
    EXPECT_EQ(b.steps, 1u);  // the first NOP, whose next PC is __bad_interrupt
    EXPECT_EQ(b.new_pc, at + 2);
    // No __bad_interrupt: the step limit ends it, counted in cycles (each
    // instruction takes at least one): 100 cycles are 25 passes of NOP,
    // NOP, RJMP (1 + 1 + 2 cycles, ATmega328P datasheet's instruction set
    // summary), 75 instructions. Mcu::run_until runs another batch for the
    // other 25.
    const avr_cycle_count_t cycle_before = avr->cycle;
    b = batch(~0u);
    EXPECT_EQ(b.ended, PredecodedCore::Ended::Count);
    EXPECT_EQ(b.steps, 75u);
    EXPECT_EQ(avr->cycle - cycle_before, 100u);
    EXPECT_EQ(avr->pc, at);
    b = batch(at + 4);
    EXPECT_EQ(b.ended, PredecodedCore::Ended::CheckPc);
    EXPECT_EQ(b.steps, 2u);
    EXPECT_EQ(b.new_pc, at + 4);
    b = batch(at);  // reached by the RJMP
    EXPECT_EQ(b.ended, PredecodedCore::Ended::CheckPc);
    EXPECT_EQ(b.steps, 3u);
    EXPECT_EQ(b.new_pc, at);
    EXPECT_EQ(core.handed_to_simavr(), 0u);
}

// Batches that run millions of instructions (a loop far from any timer):
// run_batch may end one with Ended::Count before the step limit (its
// instruction count shares a counter with the cycles, and has room for
// about a million), and the batches after it go on exactly where it
// stopped. The NOP, NOP, RJMP loop again: 4 cycles and 3 instructions a
// pass (ATmega328P instruction set summary), so 4 000 000 cycles are
// 1 000 000 passes, 3 000 000 instructions, and the last, an RJMP, ends
// exactly at the cycle limit: that batch ends with Ended::TimerDue.
TEST(PredecodedCore, LongRunsOfBatchesCountEveryInstructionAndCycle) {
    const ElfImage elf = ElfImage::load(test::firmware("busy_poll"));
    Mcu mcu(elf, McuOptions{});
    avr_t* avr = mcu.avr();
    const avr_flashaddr_t at = (avr->flashend + 1) - 64;
    put_word(avr, at, 0x0000);
    put_word(avr, at + 2, 0x0000);
    put_word(avr, at + 4, 0xcffd);
    const std::uint32_t code_end_minus_one = avr->flashend - 1;
    PredecodedCore core(avr, code_end_minus_one, ~0u);
    avr->pc = at;
    const avr_cycle_count_t cycle_before = avr->cycle;
    const avr_cycle_count_t limit = cycle_before + 4'000'000;
    std::uint64_t steps = 0;
    int batches = 0;
    PredecodedCore::Batch b;
    do {
        const PredecodedCore::BatchLimits limits{limit, 10'000'000, code_end_minus_one, ~0u, 0};
        b = core.run_batch<false>(avr, limits, nullptr);
        steps += b.steps;
        ASSERT_LT(++batches, 100);
        if (b.ended != PredecodedCore::Ended::TimerDue) {
            ASSERT_EQ(b.ended, PredecodedCore::Ended::Count);
        }
    } while (b.ended == PredecodedCore::Ended::Count);
    EXPECT_EQ(b.ended, PredecodedCore::Ended::TimerDue);
    EXPECT_GT(batches, 1);  // more instructions than one batch counts
    EXPECT_EQ(steps, 3'000'000u);
    EXPECT_EQ(avr->cycle, limit);
    EXPECT_EQ(avr->pc, at + 4);  // the RJMP, left for Mcu to finish
    EXPECT_EQ(b.new_pc, at);
    EXPECT_EQ(core.handed_to_simavr(), 0u);
}

// ELPM (all three forms), EICALL and EIJMP are the core's own since the
// ATmega2560 firmware (Marlin: 1.2 M of them on a homing job) handed them
// to avr_run_one, each ending a batch. core_sweep_far runs every form
// (RAMPZ 0..3, Z at each bank's ends, Z+ carrying into RAMPZ); the
// instruction-by-instruction test above compares it with avr_run_one.
// Here: the batches run it to its end with nothing handed over but the
// final SLEEP (power-down with interrupts off, which halts).
TEST(PredecodedCore, FarFlashAndFarJumpsRunInTheBatch) {
    const ElfImage elf = ElfImage::load(test::firmware("core_sweep_far"));
    Mcu mcu(elf, McuOptions{});
    ASSERT_NE(mcu.predecoded_core(), nullptr);
    EXPECT_EQ(mcu.run_until(16'000'000), StopReason::Halted);
    EXPECT_EQ(mcu.predecoded_core()->handed_to_simavr(), 1u);
}

}  // namespace
}  // namespace avrbench
