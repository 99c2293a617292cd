// A predecoded instruction core: each flash word is decoded once into a
// slot (what the instruction is, its operands, its branch target), and the
// run loop executes the slot instead of simavr's avr_run_one, which decodes
// every instruction every time it runs (sim_core.c, ~88 host instructions
// per AVR instruction on a traced grbl job; docs/PERFORMANCE.md).
//
// It is simavr's core, not a new one: run_one(avr) has avr_run_one's
// contract with run_cycle_limit 1 (the only limit the bench runs with,
// core/SimavrStep.hpp) - one instruction, avr->cycle advanced by its cycles,
// avr->pc left alone, the new PC returned - and every instruction it
// executes itself does exactly what simavr 1.6's avr_run_one does,
// its quirks included (an RJMP wraps modulo the flash size, a branch does
// not; the flags of every ALU instruction; 0xF1F1 is a branch). IN, OUT,
// SBI, CBI, SBIS and SBIC on an I/O register with callbacks or IRQs call
// them as simavr's _avr_get_ram/_avr_set_r do. Everything else is handed
// to avr_run_one before any state changes: loads and stores that reach such
// a register, SREG through the data space, SEI/CLI/RETI (interrupt state),
// SLEEP, BREAK, WDR, SPM, ELPM/EIJMP/EICALL, a data address outside RAM, a
// PC past the flash, invalid opcodes, and every access while simavr's own
// GDB stub is attached (its watchpoints).
// Exactness is proven instruction by instruction against avr_run_one on
// every firmware the build makes (tests/core/test_predecoded_core.cpp) and
// by every run-loop, scenario and golden test, which run on this core.
//
// Flash that changes (SPM, a boot loader writing the application, a
// debugger) needs no invalidation call: a slot remembers the opcode word it
// was decoded from and is decoded again when the flash no longer holds it.
// The second word of LDS/STS/JMP/CALL is read from flash when they run.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>

extern "C" {
#include <sim_avr.h>
#include <sim_core.h>
}

namespace avrbench {

struct PcEdgeMap;
namespace predecoded_detail {
struct Machine;
}

class PredecodedCore {
public:
    explicit PredecodedCore(const avr_t* avr);

    // avr_run_one for one instruction (see above).
    __attribute__((always_inline)) avr_flashaddr_t run_one(avr_t* avr);

    // What Mcu::run_until's fast path checks after every instruction.
    struct BatchLimits {
        avr_cycle_count_t cycle;           // the first cycle timer's `when`
        std::uint32_t max_steps;           // instructions at most
        std::uint32_t code_end_minus_one;  // a new PC with PC - 1 at or past it is checked
        std::uint32_t bad_interrupt_pc;
        std::uint16_t stack_floor;
    };
    enum class Ended {
        HandOver,  // in front of an instruction avr_run_one must execute (or a PC past the flash)
        TimerDue,  // the last instruction reached limits.cycle: avr->pc is still its PC, new_pc where it goes
        CheckPc,   // the last instruction's new PC or SP needs the crash oracles: avr->pc is still its PC
        Count,     // max_steps executed
    };
    struct Batch {
        std::uint32_t steps = 0;
        Ended ended = Ended::HandOver;
        avr_flashaddr_t new_pc = 0;
    };
    // Instructions executed back to back, exactly as that many run_one calls
    // in Mcu::run_until's fast path would, as long as each is one this core
    // executes itself (they call nothing in simavr: no cycle timer, IRQ or
    // interrupt state can change among them, so only the timer cycle, the
    // step count and the PC/SP oracles need checking). visit(new_pc) sees
    // every instruction that ends with Count or goes on.
    // With kCover, every such instruction's new PC goes into `edges` (fuzzing).
    template <bool kCover>
    Batch run_batch(avr_t* avr, const BatchLimits& limits, PcEdgeMap* edges);

    // Instructions executed here and handed to avr_run_one (tests, perf).
    std::uint64_t handed_to_simavr() const { return handed_; }

    enum Kind : std::uint8_t {
        kUndecoded = 0,  // calloc'd slots start here
        kSimavr,         // avr_run_one executes it
        kNop,
        kCpc, kAdd, kSbc, kMovw, kMuls, kMulsu, kFmul, kFmuls, kFmulsu,
        kSub, kCpse, kCp, kAdc, kAnd, kEor, kOr, kMov,
        kCpi, kSbci, kSubi, kOri, kAndi,
        kLddZ, kStdZ, kLddY, kStdY,
        kSregSet, kSregClear,  // BSET/BCLR of any flag but I
        kLpmR0, kLpm, kLpmInc, kLds, kSts,
        kLdX, kStX, kLdY, kStY, kLdZ, kStZ,  // operand b: 0 plain, 1 post-increment, 2 pre-decrement
        kPop, kPush,
        kCom, kNeg, kSwap, kInc, kAsr, kLsr, kRor, kDec,
        kJmp, kCall, kAdiw, kSbiw, kSbic, kSbis, kMul,
        kOut, kIn, kCbi, kSbi,
        kRjmp, kRcall, kLdi, kBrbs, kBrbc, kBld, kBst, kSbrc, kSbrs,
        kIjmp, kIcall, kRet,
        kKinds
    };

    struct Slot {
        std::uint16_t word;     // the opcode this slot was decoded from
        Kind kind;
        std::uint8_t a;         // Rd, Rh, the I/O data address, the pointer register
        std::uint8_t b;         // Rr, the immediate K, q, a bit number, the X/Y/Z mode
        std::uint8_t c;         // JMP/CALL: address bits 16..21
        std::uint8_t flags;     // kMovesSp
        std::uint8_t unused;
        std::uint32_t target;   // RJMP/RCALL/branch: the new PC in bytes
    };
    static_assert(sizeof(Slot) == 12);
    static constexpr std::uint8_t kMovesSp = 1;  // the instruction may store to SPL/SPH

    // The slot for `word` at byte address `pc` (public for the tests).
    static Slot decode(const avr_t* avr, std::uint16_t word, avr_flashaddr_t pc);

private:
    __attribute__((always_inline)) static Slot* slot_at(Slot* slots, const predecoded_detail::Machine& m, avr_flashaddr_t pc);
    enum class Done : std::uint8_t {
        HandOver,      // nothing changed: avr_run_one must execute it
        Plain,         // executed, nothing in simavr called
        CalledSimavr,  // executed, I/O callbacks or IRQs of simavr called (they may add timers or raise interrupts)
    };
    // One instruction's effect (avr->cycle was `cycle_before` when it began).
    __attribute__((always_inline)) Done execute(const predecoded_detail::Machine& m, const Slot& slot, avr_flashaddr_t pc,
                                                avr_cycle_count_t cycle_before, avr_flashaddr_t& new_pc, int& cycles);

    // The kinds that may store to SPL/SPH (when those have no callbacks).
    static constexpr bool moves_sp(Kind k) {
        switch (k) {
            case kStdZ: case kStdY: case kSts: case kStX: case kStY: case kStZ:
            case kPush: case kPop: case kCall: case kRcall: case kIcall: case kRet: case kOut:
                return true;
            default:
                return false;
        }
    }

    struct FreeDeleter {
        void operator()(Slot* p) const { std::free(p); }
    };
    std::unique_ptr<Slot[], FreeDeleter> slots_;
    std::uint64_t handed_ = 0;
};

namespace predecoded_detail {

// The core's view of avr_t, read once per batch: a store through data[]
// (uint8_t, which may alias anything) would otherwise make the compiler
// reload every avr_t field after each instruction. Nothing a batch runs
// changes them (simavr's I/O callbacks do not either).
struct Machine {
    explicit Machine(avr_t* a)
        : avr(a), data(a->data), sreg(a->sreg), flash(a->flash), ramend(a->ramend), flashend(a->flashend),
          address_size(a->address_size), watched(a->gdb != nullptr) {}
    avr_t* avr;
    std::uint8_t* data;
    std::uint8_t* sreg;
    const std::uint8_t* flash;
    std::uint32_t ramend;
    std::uint32_t flashend;
    int address_size;
    bool watched;  // simavr's GDB stub is attached (its watchpoints see data accesses)
};

__attribute__((always_inline)) inline std::uint16_t flash16(const std::uint8_t* flash, avr_flashaddr_t addr) {
    return static_cast<std::uint16_t>(flash[addr] | (flash[addr + 1] << 8));
}

// _avr_is_instruction_32_bits (sim_core.c).
__attribute__((always_inline)) inline bool is_32_bit(const std::uint8_t* flash, avr_flashaddr_t pc) {
    const std::uint16_t o = flash16(flash, pc) & 0xfc0f;
    return o == 0x9200 || o == 0x9000 || o == 0x940c || o == 0x940d || o == 0x940e || o == 0x940f;
}

// True when simavr's _avr_set_ram(addr, v) (kWrite) would only store v in
// data[addr], or its _avr_get_ram(addr) only read it: a register, an I/O
// slot with no callback that way and no IRQ (not SREG), or RAM up to
// RAMEND, with no GDB stub watching.
template <bool kWrite>
__attribute__((always_inline)) inline bool plain_access(const Machine& m, std::uint16_t addr) {
    if (addr > m.ramend || m.watched) return false;
    if (addr < 32 || addr >= MAX_IOs + 31) return true;
    if (addr == R_SREG) return false;
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    return (kWrite ? io.w.c == nullptr : io.r.c == nullptr) && io.irq == nullptr;
}
__attribute__((always_inline)) inline bool plain_write(const Machine& m, std::uint16_t addr) { return plain_access<true>(m, addr); }
__attribute__((always_inline)) inline bool plain_read(const Machine& m, std::uint16_t addr) { return plain_access<false>(m, addr); }

// An I/O register this core may read or write itself through simavr's
// callbacks, as _avr_get_ram/_avr_set_r do: not SREG, within RAM, no GDB stub.
__attribute__((always_inline)) inline bool io_callable(const Machine& m, std::uint16_t addr) {
    return addr >= 32 && addr < MAX_IOs + 31 && addr != R_SREG && addr <= m.ramend && !m.watched;
}

// Raises the register's IRQs with `v`: the whole byte, then each bit
// (what _avr_get_ram and _avr_set_r do when avr_iomem_getirq made them).
inline void io_raise(avr_irq_t* irq, std::uint8_t v) {
    avr_raise_irq(irq + AVR_IOMEM_IRQ_ALL, v);
    for (int i = 0; i < 8; i++) avr_raise_irq(irq + i, (v >> i) & 1);
}

// _avr_get_ram(addr) for an io_callable address: the read callback's value
// stored, the IRQs raised, then the byte as avr_core_watch_read returns it.
__attribute__((always_inline)) inline std::uint8_t io_read(const Machine& m, std::uint16_t addr) {
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    if (io.r.c) m.data[addr] = io.r.c(m.avr, addr, io.r.param);
    if (io.irq) io_raise(io.irq, m.data[addr]);
    return m.data[addr];
}

// _avr_set_r(addr, v) for an io_callable address.
__attribute__((always_inline)) inline void io_write(const Machine& m, std::uint16_t addr, std::uint8_t v) {
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    if (io.w.c)
        io.w.c(m.avr, addr, v, io.w.param);
    else
        m.data[addr] = v;
    if (io.irq) io_raise(io.irq, v);
}

// The stack pointer's own writes (_avr_sp_set) are plain.
__attribute__((always_inline)) inline bool plain_sp(const Machine& m) { return plain_write(m, R_SPL) && plain_write(m, R_SPH); }

// A return address of `size` bytes pushed downwards from `sp`
// (_avr_push_addr), or popped upwards from `sp` (_avr_pop_addr), and the
// stack pointer update after it, are all plain.
__attribute__((always_inline)) inline bool plain_push(const Machine& m, std::uint16_t sp, int size) {
    for (int i = 0; i < size; i++)
        if (!plain_write(m, static_cast<std::uint16_t>(sp - i))) return false;
    return plain_sp(m);
}
__attribute__((always_inline)) inline bool plain_pop(const Machine& m, std::uint16_t sp, int size) {
    for (int i = 0; i < size; i++)
        if (!plain_read(m, static_cast<std::uint16_t>(sp + i))) return false;
    return plain_sp(m);
}

__attribute__((always_inline)) inline std::uint16_t sp_of(const std::uint8_t* data) {
    return static_cast<std::uint16_t>(data[R_SPL] | (data[R_SPH] << 8));
}
__attribute__((always_inline)) inline void set_sp(std::uint8_t* data, std::uint16_t sp) {
    data[R_SPL] = static_cast<std::uint8_t>(sp);
    data[R_SPH] = static_cast<std::uint8_t>(sp >> 8);
}

// _avr_push_addr once plain_push said yes: the return address in words,
// low byte first, downwards from SP, then SP below it.
__attribute__((always_inline)) inline void push_return(const Machine& m, avr_flashaddr_t return_pc) {
    std::uint16_t sp = sp_of(m.data);
    avr_flashaddr_t ret = return_pc >> 1;
    for (int i = 0; i < m.address_size; i++, ret >>= 8, sp--) m.data[sp] = static_cast<std::uint8_t>(ret);
    set_sp(m.data, sp);
}

// The flag helpers of sim_core.c, expression for expression.
__attribute__((always_inline)) inline void flags_zns(std::uint8_t* s, std::uint8_t res) {
    s[S_Z] = res == 0;
    s[S_N] = (res >> 7) & 1;
    s[S_S] = s[S_N] ^ s[S_V];
}
__attribute__((always_inline)) inline void flags_zns16(std::uint8_t* s, std::uint16_t res) {
    s[S_Z] = res == 0;
    s[S_N] = static_cast<std::uint8_t>((res >> 15) & 1);
    s[S_S] = s[S_N] ^ s[S_V];
}
__attribute__((always_inline)) inline void flags_add_zns(std::uint8_t* s, std::uint8_t res, std::uint8_t rd, std::uint8_t rr) {
    const std::uint8_t add_carry = static_cast<std::uint8_t>((rd & rr) | (rr & ~res) | (~res & rd));
    s[S_H] = (add_carry >> 3) & 1;
    s[S_C] = (add_carry >> 7) & 1;
    s[S_V] = (((rd & rr & ~res) | (~rd & ~rr & res)) >> 7) & 1;
    flags_zns(s, res);
}
__attribute__((always_inline)) inline void flags_sub_common(std::uint8_t* s, std::uint8_t res, std::uint8_t rd, std::uint8_t rr) {
    const std::uint8_t sub_carry = static_cast<std::uint8_t>((~rd & rr) | (rr & res) | (res & ~rd));
    s[S_H] = (sub_carry >> 3) & 1;
    s[S_C] = (sub_carry >> 7) & 1;
    s[S_V] = (((rd & ~rr & ~res) | (~rd & rr & res)) >> 7) & 1;
}
__attribute__((always_inline)) inline void flags_sub_zns(std::uint8_t* s, std::uint8_t res, std::uint8_t rd, std::uint8_t rr) {
    flags_sub_common(s, res, rd, rr);
    flags_zns(s, res);
}
__attribute__((always_inline)) inline void flags_Rzns(std::uint8_t* s, std::uint8_t res) {
    if (res) s[S_Z] = 0;
    s[S_N] = (res >> 7) & 1;
    s[S_S] = s[S_N] ^ s[S_V];
}
__attribute__((always_inline)) inline void flags_sub_Rzns(std::uint8_t* s, std::uint8_t res, std::uint8_t rd, std::uint8_t rr) {
    flags_sub_common(s, res, rd, rr);
    flags_Rzns(s, res);
}
__attribute__((always_inline)) inline void flags_zcvs(std::uint8_t* s, std::uint8_t res, std::uint8_t vr) {
    s[S_Z] = res == 0;
    s[S_C] = vr & 1;
    s[S_V] = s[S_N] ^ s[S_C];
    s[S_S] = s[S_N] ^ s[S_V];
}
__attribute__((always_inline)) inline void flags_zcnvs(std::uint8_t* s, std::uint8_t res, std::uint8_t vr) {
    s[S_Z] = res == 0;
    s[S_C] = vr & 1;
    s[S_N] = res >> 7;
    s[S_V] = s[S_N] ^ s[S_C];
    s[S_S] = s[S_N] ^ s[S_V];
}
__attribute__((always_inline)) inline void flags_znv0s(std::uint8_t* s, std::uint8_t res) {
    s[S_V] = 0;
    flags_zns(s, res);
}

}  // namespace predecoded_detail

__attribute__((always_inline)) inline PredecodedCore::Slot* PredecodedCore::slot_at(Slot* slots, const predecoded_detail::Machine& m,
                                                                                avr_flashaddr_t pc) {
    Slot* slot = &slots[pc >> 1];
    const std::uint16_t word = predecoded_detail::flash16(m.flash, pc);
    if (__builtin_expect(slot->word != word || slot->kind == kUndecoded, 0)) *slot = decode(m.avr, word, pc);
    return slot;
}

__attribute__((always_inline)) inline avr_flashaddr_t PredecodedCore::run_one(avr_t* avr) {
    const avr_flashaddr_t pc = avr->pc;
    if (__builtin_expect(pc < avr->flashend, 1)) {
        const predecoded_detail::Machine m(avr);
        avr_flashaddr_t new_pc;
        int cycles;
        if (__builtin_expect(execute(m, *slot_at(slots_.get(), m, pc), pc, avr->cycle, new_pc, cycles) != Done::HandOver, 1)) {
            avr->cycle += static_cast<avr_cycle_count_t>(cycles);
            return new_pc;
        }
    }
    ++handed_;
    return avr_run_one(avr);
}

__attribute__((always_inline)) inline PredecodedCore::Done PredecodedCore::execute(const predecoded_detail::Machine& m, const Slot& slot_ref, avr_flashaddr_t pc,
                                                                           avr_cycle_count_t cycle_before, avr_flashaddr_t& new_pc_out,
                                                                           int& cycles_out) {
    using namespace predecoded_detail;
    const Slot* const slot = &slot_ref;
    std::uint8_t* const data = m.data;
    std::uint8_t* const sreg = m.sreg;
    const std::uint8_t a = slot->a, b = slot->b;
    avr_flashaddr_t new_pc = pc + 2;
    int cycle = 1;
    // Before simavr's I/O callbacks run: they see avr->pc at this
    // instruction and avr->cycle before it, as inside avr_run_one.
    Done done = Done::Plain;
#define AVRBENCH_BEFORE_CALLBACKS()     \
    do {                                \
        m.avr->pc = pc;                 \
        m.avr->cycle = cycle_before;    \
        done = Done::CalledSimavr;      \
    } while (0)
    // The skip of CPSE/SBRC/SBRS/SBIC/SBIS: one word or two, one cycle or two.
#define AVRBENCH_SKIP()                                   \
    do {                                                  \
        const int words = is_32_bit(m.flash, new_pc) ? 2 : 1; \
        new_pc += 2u * static_cast<unsigned>(words);      \
        cycle += words;                                   \
    } while (0)
    switch (slot->kind) {
        case kNop: break;
        case kCpc: {
            const std::uint8_t vd = data[a], vr = data[b];
            const std::uint8_t res = static_cast<std::uint8_t>(vd - vr - sreg[S_C]);
            flags_sub_Rzns(sreg, res, vd, vr);
        } break;
        case kAdd: {
            const std::uint8_t vd = data[a], vr = data[b];
            const std::uint8_t res = static_cast<std::uint8_t>(vd + vr);
            data[a] = res;
            flags_add_zns(sreg, res, vd, vr);
        } break;
        case kSbc: {
            const std::uint8_t vd = data[a], vr = data[b];
            const std::uint8_t res = static_cast<std::uint8_t>(vd - vr - sreg[S_C]);
            data[a] = res;
            flags_sub_Rzns(sreg, res, vd, vr);
        } break;
        case kMovw: {
            const std::uint16_t vr = static_cast<std::uint16_t>(data[b] | (data[b + 1] << 8));
            data[a] = static_cast<std::uint8_t>(vr);
            data[a + 1] = static_cast<std::uint8_t>(vr >> 8);
        } break;
        case kMuls: {
            const std::int16_t res = static_cast<std::int16_t>(static_cast<std::int8_t>(data[b]) * static_cast<std::int8_t>(data[a]));
            data[0] = static_cast<std::uint8_t>(res);
            data[1] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(res) >> 8);
            sreg[S_C] = static_cast<std::uint8_t>((res >> 15) & 1);
            sreg[S_Z] = res == 0;
            cycle++;
        } break;
#define AVRBENCH_MUL_FORM(kind, R, D, shift)                                               \
        case kind: {                                                                       \
            std::int16_t res = static_cast<std::int16_t>((R)data[b] * (D)data[a]);         \
            const std::uint8_t c = static_cast<std::uint8_t>((res >> 15) & 1);            \
            if (shift) res = static_cast<std::int16_t>(res << 1);                          \
            cycle++;                                                                       \
            data[0] = static_cast<std::uint8_t>(res);                                      \
            data[1] = static_cast<std::uint8_t>(static_cast<std::uint16_t>(res) >> 8);     \
            sreg[S_C] = c;                                                                 \
            sreg[S_Z] = res == 0;                                                          \
        } break;
        // MULSU, FMUL, FMULS, FMULSU: the operand types and the shift of sim_core.c.
        AVRBENCH_MUL_FORM(kMulsu, std::uint8_t, std::int8_t, false)
        AVRBENCH_MUL_FORM(kFmul, std::uint8_t, std::uint8_t, true)
        AVRBENCH_MUL_FORM(kFmuls, std::int8_t, std::int8_t, true)
        AVRBENCH_MUL_FORM(kFmulsu, std::uint8_t, std::int8_t, true)
#undef AVRBENCH_MUL_FORM
        case kSub: {
            const std::uint8_t vd = data[a], vr = data[b];
            const std::uint8_t res = static_cast<std::uint8_t>(vd - vr);
            data[a] = res;
            flags_sub_zns(sreg, res, vd, vr);
        } break;
        case kCpse:
            if (data[a] == data[b]) AVRBENCH_SKIP();
            break;
        case kCp: {
            const std::uint8_t vd = data[a], vr = data[b];
            flags_sub_zns(sreg, static_cast<std::uint8_t>(vd - vr), vd, vr);
        } break;
        case kAdc: {
            const std::uint8_t vd = data[a], vr = data[b];
            const std::uint8_t res = static_cast<std::uint8_t>(vd + vr + sreg[S_C]);
            data[a] = res;
            flags_add_zns(sreg, res, vd, vr);
        } break;
        case kAnd: {
            const std::uint8_t res = data[a] & data[b];
            data[a] = res;
            flags_znv0s(sreg, res);
        } break;
        case kEor: {
            const std::uint8_t res = data[a] ^ data[b];
            data[a] = res;
            flags_znv0s(sreg, res);
        } break;
        case kOr: {
            const std::uint8_t res = data[a] | data[b];
            data[a] = res;
            flags_znv0s(sreg, res);
        } break;
        case kMov: data[a] = data[b]; break;
        case kCpi: {
            const std::uint8_t vh = data[a];
            flags_sub_zns(sreg, static_cast<std::uint8_t>(vh - b), vh, b);
        } break;
        case kSbci: {
            const std::uint8_t vh = data[a];
            const std::uint8_t res = static_cast<std::uint8_t>(vh - b - sreg[S_C]);
            data[a] = res;
            flags_sub_Rzns(sreg, res, vh, b);
        } break;
        case kSubi: {
            const std::uint8_t vh = data[a];
            const std::uint8_t res = static_cast<std::uint8_t>(vh - b);
            data[a] = res;
            flags_sub_zns(sreg, res, vh, b);
        } break;
        case kOri: {
            const std::uint8_t res = data[a] | b;
            data[a] = res;
            flags_znv0s(sreg, res);
        } break;
        case kAndi: {
            const std::uint8_t res = data[a] & b;
            data[a] = res;
            flags_znv0s(sreg, res);
        } break;
        case kLddZ: case kLddY: {
            const std::uint8_t base = slot->kind == kLddZ ? R_ZL : R_YL;
            const std::uint16_t addr = static_cast<std::uint16_t>((data[base] | (data[base + 1] << 8)) + b);
            if (!plain_read(m, addr)) goto hand_over;
            data[a] = data[addr];
            cycle++;
        } break;
        case kStdZ: case kStdY: {
            const std::uint8_t base = slot->kind == kStdZ ? R_ZL : R_YL;
            const std::uint16_t addr = static_cast<std::uint16_t>((data[base] | (data[base + 1] << 8)) + b);
            if (!plain_write(m, addr)) goto hand_over;
            data[addr] = data[a];
            cycle++;
        } break;
        case kSregSet: sreg[b] = 1; break;
        case kSregClear: sreg[b] = 0; break;
        case kLpmR0: {
            const std::uint16_t z = static_cast<std::uint16_t>(data[R_ZL] | (data[R_ZH] << 8));
            if (z > m.flashend) goto hand_over;
            cycle += 2;
            data[0] = m.flash[z];
        } break;
        case kLpm: case kLpmInc: {
            std::uint16_t z = static_cast<std::uint16_t>(data[R_ZL] | (data[R_ZH] << 8));
            if (z > m.flashend) goto hand_over;
            data[a] = m.flash[z];
            if (slot->kind == kLpmInc) {
                z++;
                data[R_ZH] = static_cast<std::uint8_t>(z >> 8);
                data[R_ZL] = static_cast<std::uint8_t>(z);
            }
            cycle += 2;
        } break;
        case kLds: {
            const std::uint16_t x = flash16(m.flash, new_pc);
            if (!plain_read(m, x)) goto hand_over;
            new_pc += 2;
            data[a] = data[x];
            cycle++;
        } break;
        case kSts: {
            const std::uint16_t x = flash16(m.flash, new_pc);
            if (!plain_write(m, x)) goto hand_over;
            new_pc += 2;
            cycle++;
            data[x] = data[a];
        } break;
        case kLdX: case kLdY: case kLdZ: {
            // LD Rd, X/X+/-X (Y, Z): the pointer is written back before Rd,
            // as simavr does (it matters for the undefined LD r26, X+).
            const std::uint8_t base = slot->kind == kLdX ? R_XL : slot->kind == kLdY ? R_YL : R_ZL;
            std::uint16_t p = static_cast<std::uint16_t>((data[base + 1] << 8) | data[base]);
            cycle++;
            if (b == 2) p--;
            if (!plain_read(m, p)) goto hand_over;
            const std::uint8_t vd = data[p];
            if (b == 1) p++;
            data[base + 1] = static_cast<std::uint8_t>(p >> 8);
            data[base] = static_cast<std::uint8_t>(p);
            data[a] = vd;
        } break;
        case kStX: case kStY: case kStZ: {
            const std::uint8_t base = slot->kind == kStX ? R_XL : slot->kind == kStY ? R_YL : R_ZL;
            const std::uint8_t vd = data[a];
            std::uint16_t p = static_cast<std::uint16_t>((data[base + 1] << 8) | data[base]);
            cycle++;
            if (b == 2) p--;
            if (!plain_write(m, p)) goto hand_over;
            data[p] = vd;
            if (b == 1) p++;
            data[base + 1] = static_cast<std::uint8_t>(p >> 8);
            data[base] = static_cast<std::uint8_t>(p);
        } break;
        case kPop: {
            const std::uint16_t sp = static_cast<std::uint16_t>(sp_of(data) + 1);
            if (!plain_read(m, sp) || !plain_sp(m)) goto hand_over;
            const std::uint8_t v = data[sp];
            set_sp(data, sp);
            data[a] = v;
            cycle++;
        } break;
        case kPush: {
            const std::uint8_t vd = data[a];
            const std::uint16_t sp = sp_of(data);
            if (!plain_write(m, sp) || !plain_sp(m)) goto hand_over;
            data[sp] = vd;
            set_sp(data, static_cast<std::uint16_t>(sp - 1));
            cycle++;
        } break;
        case kCom: {
            const std::uint8_t res = static_cast<std::uint8_t>(0xff - data[a]);
            data[a] = res;
            flags_znv0s(sreg, res);
            sreg[S_C] = 1;
        } break;
        case kNeg: {
            const std::uint8_t vd = data[a];
            const std::uint8_t res = static_cast<std::uint8_t>(0x00 - vd);
            data[a] = res;
            sreg[S_H] = ((res >> 3) | (vd >> 3)) & 1;
            sreg[S_V] = res == 0x80;
            sreg[S_C] = res != 0;
            flags_zns(sreg, res);
        } break;
        case kSwap: {
            const std::uint8_t vd = data[a];
            data[a] = static_cast<std::uint8_t>((vd >> 4) | (vd << 4));
        } break;
        case kInc: {
            const std::uint8_t res = static_cast<std::uint8_t>(data[a] + 1);
            data[a] = res;
            sreg[S_V] = res == 0x80;
            flags_zns(sreg, res);
        } break;
        case kAsr: {
            const std::uint8_t vd = data[a];
            const std::uint8_t res = static_cast<std::uint8_t>((vd >> 1) | (vd & 0x80));
            data[a] = res;
            flags_zcnvs(sreg, res, vd);
        } break;
        case kLsr: {
            const std::uint8_t vd = data[a];
            const std::uint8_t res = static_cast<std::uint8_t>(vd >> 1);
            data[a] = res;
            sreg[S_N] = 0;
            flags_zcvs(sreg, res, vd);
        } break;
        case kRor: {
            const std::uint8_t vd = data[a];
            const std::uint8_t res = static_cast<std::uint8_t>((sreg[S_C] ? 0x80 : 0) | vd >> 1);
            data[a] = res;
            flags_zcnvs(sreg, res, vd);
        } break;
        case kDec: {
            const std::uint8_t res = static_cast<std::uint8_t>(data[a] - 1);
            data[a] = res;
            sreg[S_V] = res == 0x7f;
            flags_zns(sreg, res);
        } break;
        case kJmp: {
            const avr_flashaddr_t target = (static_cast<avr_flashaddr_t>(slot->c) << 16) | flash16(m.flash, new_pc);
            new_pc = target << 1;
            cycle += 2;
        } break;
        case kCall: {
            // _avr_push_addr: the word address, low byte first, downwards.
            const avr_flashaddr_t target = (static_cast<avr_flashaddr_t>(slot->c) << 16) | flash16(m.flash, new_pc);
            if (!plain_push(m, sp_of(data), m.address_size)) goto hand_over;
            push_return(m, new_pc + 2);
            cycle += 1 + m.address_size;
            new_pc = target << 1;
        } break;
        case kAdiw: case kSbiw: {
            const std::uint16_t vp = static_cast<std::uint16_t>(data[a] | (data[a + 1] << 8));
            const std::uint16_t res = static_cast<std::uint16_t>(slot->kind == kAdiw ? vp + b : vp - b);
            data[a + 1] = static_cast<std::uint8_t>(res >> 8);
            data[a] = static_cast<std::uint8_t>(res);
            if (slot->kind == kAdiw) {
                sreg[S_V] = ((~vp & res) >> 15) & 1;
                sreg[S_C] = ((~res & vp) >> 15) & 1;
            } else {
                sreg[S_V] = ((vp & ~res) >> 15) & 1;
                sreg[S_C] = ((res & ~vp) >> 15) & 1;
            }
            flags_zns16(sreg, res);
            cycle++;
        } break;
        case kSbic: case kSbis: {
            std::uint8_t v;
            if (plain_read(m, a)) {
                v = data[a];
            } else {
                if (!io_callable(m, a)) goto hand_over;
                AVRBENCH_BEFORE_CALLBACKS();
                v = io_read(m, a);
            }
            const bool set = (v & b) != 0;
            if (set == (slot->kind == kSbis)) AVRBENCH_SKIP();
        } break;
        case kCbi: case kSbi: {
            // 1001 10x0 AAAA Abbb: read, change one bit, write (2 cycles).
            if (!io_callable(m, a)) goto hand_over;
            AVRBENCH_BEFORE_CALLBACKS();
            const std::uint8_t v = io_read(m, a);
            io_write(m, a, static_cast<std::uint8_t>(slot->kind == kSbi ? (v | b) : (v & ~b)));
            cycle++;
        } break;
        case kMul: {
            const std::uint16_t res = static_cast<std::uint16_t>(data[a] * data[b]);
            cycle++;
            data[0] = static_cast<std::uint8_t>(res);
            data[1] = static_cast<std::uint8_t>(res >> 8);
            sreg[S_Z] = res == 0;
            sreg[S_C] = static_cast<std::uint8_t>((res >> 15) & 1);
        } break;
        case kOut:
            if (plain_write(m, a)) {
                data[a] = data[b];
                break;
            }
            if (!io_callable(m, a)) goto hand_over;
            AVRBENCH_BEFORE_CALLBACKS();
            io_write(m, a, data[b]);
            break;
        case kIn:
            if (b == R_SREG) {
                if (m.watched) goto hand_over;
                std::uint8_t v = 0;
                for (int i = 0; i < 8; i++)
                    if (sreg[i]) v |= static_cast<std::uint8_t>(1 << i);
                data[R_SREG] = v;
                data[a] = v;
                break;
            }
            if (plain_read(m, b)) {
                data[a] = data[b];
                break;
            }
            if (!io_callable(m, b)) goto hand_over;
            AVRBENCH_BEFORE_CALLBACKS();
            data[a] = io_read(m, b);
            break;
        case kRjmp:
            new_pc = slot->target;
            cycle++;
            break;
        case kRcall: {
            if (!plain_push(m, sp_of(data), m.address_size)) goto hand_over;
            push_return(m, new_pc);
            cycle += m.address_size;
            new_pc = slot->target;
        } break;
        case kLdi: data[a] = b; break;
        case kBrbs:
            if (sreg[b]) {
                cycle++;
                new_pc = slot->target;
            }
            break;
        case kBrbc:
            if (!sreg[b]) {
                cycle++;
                new_pc = slot->target;
            }
            break;
        case kBld: {
            const std::uint8_t mask = static_cast<std::uint8_t>(1 << b);
            data[a] = static_cast<std::uint8_t>((data[a] & ~mask) | (sreg[S_T] ? mask : 0));
        } break;
        case kBst: sreg[S_T] = (data[a] >> b) & 1; break;
        case kSbrc:
            if (!(data[a] & (1 << b))) AVRBENCH_SKIP();
            break;
        case kSbrs:
            if (data[a] & (1 << b)) AVRBENCH_SKIP();
            break;
        case kIjmp:
            new_pc = static_cast<avr_flashaddr_t>(data[R_ZL] | (data[R_ZH] << 8)) << 1;
            cycle++;
            break;
        case kIcall: {
            if (!plain_push(m, sp_of(data), m.address_size)) goto hand_over;
            const avr_flashaddr_t z = static_cast<avr_flashaddr_t>(data[R_ZL] | (data[R_ZH] << 8));
            push_return(m, new_pc);
            cycle += m.address_size - 1;
            new_pc = z << 1;
            cycle++;
        } break;
        case kRet: {
            // _avr_pop_addr: high byte first, upwards.
            const int size = m.address_size;
            std::uint16_t sp = static_cast<std::uint16_t>(sp_of(data) + 1);
            if (!plain_pop(m, sp, size)) goto hand_over;
            avr_flashaddr_t res = 0;
            for (int i = 0; i < size; i++, sp++) res = (res << 8) | data[sp];
            res <<= 1;
            set_sp(data, static_cast<std::uint16_t>(sp - 1));
            new_pc = res;
            cycle += 1 + size;
        } break;
        case kUndecoded:
        case kSimavr:
            goto hand_over;
        default:
            __builtin_unreachable();  // decode() makes no other kind
    }
#undef AVRBENCH_SKIP
#undef AVRBENCH_BEFORE_CALLBACKS
    new_pc_out = new_pc;
    cycles_out = cycle;
    return done;
hand_over:
    return Done::HandOver;
}

}  // namespace avrbench
