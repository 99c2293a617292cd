// A predecoded instruction core: each flash word is decoded once into a
// slot (what the instruction is, its operands, its branch target), and the
// run loop executes the slot instead of simavr's avr_run_one, which decodes
// every instruction every time it runs (sim_core.c, ~88 host instructions
// per AVR instruction on a traced grbl job; docs/PERFORMANCE.md).
//
// It is simavr's core, not a new one: run_one(avr) has avr_run_one's
// contract with run_cycle_limit 1 (the only limit the bench runs with,
// mcu/SimavrStep.hpp) - one instruction, avr->cycle advanced by its cycles,
// avr->pc left alone, the new PC returned - and every instruction it
// executes itself does exactly what simavr 1.6's avr_run_one does,
// its quirks included (an RJMP wraps modulo the flash size, a branch does
// not; the flags of every ALU instruction; 0xF1F1 is a branch). IN, OUT,
// SBI, CBI, SBIS, SBIC and the loads and stores (LD, LDD, LDS, ST, STD,
// STS) on an I/O register with callbacks or IRQs call them as simavr's
// _avr_get_ram/_avr_set_r do; CLI, SEI and OUT to SREG set the flags
// through simavr's own avr_sreg_set (interrupt_state). Everything else is
// handed to avr_run_one before any state changes: SREG through a load or
// store, RETI, SLEEP, BREAK, WDR, SPM, ELPM past the flash, a data address outside RAM, a
// PC past the flash, invalid opcodes, and every access while simavr's own
// GDB stub is attached (its watchpoints).
// On x86-64, run_batch runs straight runs of instructions as host code
// (mcu/BlockTranslator.hpp), each entered where a run begins: a slot
// heading one has the handler kBlock.
// Exactness is proven instruction by instruction against avr_run_one on
// every firmware the build makes (tests/core/test_predecoded_core.cpp) and
// by every run-loop, scenario and golden test, which run on this core.
//
// Flash that changes: run_one (the general step) compares a slot's opcode
// words with flash and decodes again when they differ. run_batch does not
// compare on each fetch; a flash write invalidates the slots it covers: an
// SPM is seen by the core's own I/O module, first in avr->io_port, before
// simavr's flash module does the write (FlashWatch below); other writers
// from outside the firmware (the debugger) call flash_written; a fuzz
// target's restore changes the board's flash_written_ token, and the next
// batch decodes everything again. JMP/CALL read their second word from
// flash when they run.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>

extern "C" {
#include <avr_ioport.h>
#include <sim_avr.h>
#include <sim_core.h>
}

namespace avrbench {

class BlockTranslator;
struct PcEdgeMap;
namespace predecoded_detail {
struct Machine;
}

// Every slot kind, in the order of PredecodedCore::Kind (the enum and
// run_batch's handler table are both made from this list). kUndecoded:
// calloc'd slots start here; kSimavr: avr_run_one executes it; the X/Y/Z
// loads and stores carry in operand b 0 (plain), 1 (post-increment) or
// 2 (pre-decrement). kBlock is never a slot's kind, only its handler: the
// slot heads a translated block (mcu/BlockTranslator.hpp), whose index is
// in its `target`.
#define AVRBENCH_PREDECODED_KINDS(X)                                                          \
    X(kUndecoded) X(kSimavr) X(kNop)                                                          \
    X(kCpc) X(kAdd) X(kSbc) X(kMovw) X(kMuls) X(kMulsu) X(kFmul) X(kFmuls) X(kFmulsu)         \
    X(kSub) X(kCpse) X(kCp) X(kAdc) X(kAnd) X(kEor) X(kOr) X(kMov)                            \
    X(kCpi) X(kSbci) X(kSubi) X(kOri) X(kAndi)                                                \
    X(kLddZ) X(kStdZ) X(kLddY) X(kStdY)                                                       \
    X(kSregSet) X(kSregClear) X(kCli) X(kSei)                                                 \
    X(kLpmR0) X(kLpm) X(kLpmInc) X(kLds) X(kSts)                                              \
    X(kLdX) X(kStX) X(kLdY) X(kStY) X(kLdZ) X(kStZ)                                           \
    X(kPop) X(kPush)                                                                          \
    X(kCom) X(kNeg) X(kSwap) X(kInc) X(kAsr) X(kLsr) X(kRor) X(kDec)                          \
    X(kJmp) X(kCall) X(kAdiw) X(kSbiw) X(kSbic) X(kSbis) X(kMul)                              \
    X(kOut) X(kIn) X(kCbi) X(kSbi)                                                            \
    X(kRjmp) X(kRcall) X(kLdi) X(kBrbs) X(kBrbc) X(kBld) X(kBst) X(kSbrc) X(kSbrs)            \
    X(kIjmp) X(kIcall) X(kRet) X(kElpm) X(kEijmp) X(kEicall)                                   \
    X(kBlock)

class PredecodedCore {
public:
    // code_end_minus_one and bad_interrupt_pc: the crash oracles' limits
    // Mcu::run_until will pass in BatchLimits (decoding records which
    // instructions can reach them; other limits later cost one re-decode).
    // translate_blocks: run straight runs of instructions as
    // host code (mcu/BlockTranslator.hpp) where the host has it.
    explicit PredecodedCore(avr_t* avr, std::uint32_t code_end_minus_one = 0, std::uint32_t bad_interrupt_pc = ~0u,
                            bool translate_blocks = true);
    ~PredecodedCore();  // unhooks from avr's I/O modules: before the avr_t is freed
    PredecodedCore(const PredecodedCore&) = delete;
    PredecodedCore& operator=(const PredecodedCore&) = delete;

    // Flash bytes [begin, end) were written from outside the firmware (a
    // debugger's memory write): run_batch decodes them again. (An SPM's
    // writes it notices itself.)
    void flash_written(avr_flashaddr_t begin, avr_flashaddr_t end);

    // avr_run_one for one instruction (see above).
    __attribute__((always_inline)) avr_flashaddr_t run_one(avr_t* avr);

    // What Mcu::run_until's fast path checks after every instruction.
    struct BatchLimits {
        avr_cycle_count_t cycle;           // the first cycle timer's `when`, or the horizon if sooner
        std::uint32_t max_steps;           // instructions at most
        std::uint32_t code_end_minus_one;  // a new PC with PC - 1 at or past it is checked
        std::uint32_t bad_interrupt_pc;
        std::uint16_t stack_floor;
        // Mcu::run_until's target: after an I/O callback moved the timers,
        // the batch's cycle limit is worked out again from the first timer
        // and this.
        avr_cycle_count_t horizon = ~avr_cycle_count_t{0};
    };
    enum class Ended {
        HandOver,  // in front of an instruction avr_run_one must execute (or a PC past the flash)
        TimerDue,  // the last instruction reached limits.cycle: avr->pc is still its PC, new_pc where it goes
        CheckPc,   // the last instruction's new PC or SP needs the crash oracles: avr->pc is still its PC
        Count,     // max_steps executed, or fewer: the step limit is counted as cycles (one at least per instruction)
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
    // Blocks translated into host code so far (0 without translation), and
    // which BlockTranslator::Op they held (bit n: Op n).
    std::size_t translated_blocks() const;
    std::uint64_t translated_ops() const;

    enum Kind : std::uint8_t {
#define AVRBENCH_KIND_ENUMERATOR(kind) kind,
        AVRBENCH_PREDECODED_KINDS(AVRBENCH_KIND_ENUMERATOR)
#undef AVRBENCH_KIND_ENUMERATOR
        kKinds
    };
    static_assert(2 * kKinds <= 256, "Slot::handler indexes both copies of the handlers in one byte");

    struct Slot {
        std::uint16_t word;     // the opcode this slot was decoded from
        Kind kind;
        std::uint8_t a;         // Rd, Rh, the I/O data address, the pointer register
        std::uint8_t b;         // Rr, the immediate K, q, a bit number, the X/Y/Z mode
        std::uint8_t c;         // JMP/CALL: address bits 16..21
        std::uint8_t flags;     // kMovesSp, kRamOperand
        std::uint8_t check;     // nonzero: after it, run_batch must test the crash oracles
        std::uint32_t target;   // RJMP/RCALL/branch: the new PC in bytes; LDS/STS: the data address
        std::uint16_t word2;    // LDS/STS: the second word `target` was decoded from
        std::uint8_t handler;   // run_batch's handler: `kind`, plus kKinds when `check` (its checked copy)
        std::uint8_t unused;
    };
    // 16 bytes: a slot's address is the flash byte address times 8.
    static_assert(sizeof(Slot) == 16);
    static constexpr std::uint8_t kMovesSp = 1;          // the instruction may store to SPL/SPH
    static constexpr std::uint8_t kRamOperand = 2;  // LDS/STS of RAM past the I/O registers (ioend), within RAMEND

    // The slot for `word` at byte address `pc` (public for the tests).
    // Its `check` is left 0: that depends on the oracles' limits.
    static Slot decode(const avr_t* avr, std::uint16_t word, avr_flashaddr_t pc);

private:
    // The slot at `pc`, decoded again when flash no longer holds its word.
    __attribute__((always_inline)) Slot* slot_at(const predecoded_detail::Machine& m, avr_flashaddr_t pc);
    // decode() and the slot's `check` for the limits in checked_for_.
    Slot decode_checked(const avr_t* avr, std::uint16_t word, avr_flashaddr_t pc) const;
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
            case kPush: case kPop: case kCall: case kRcall: case kIcall: case kEicall: case kRet: case kOut:
                return true;
            default:
                return false;
        }
    }

    struct FreeDeleter {
        void operator()(void* p) const { std::free(p); }
    };
    std::unique_ptr<Slot[], FreeDeleter> slots_;
    std::size_t slot_count_ = 0;
    // The limits the slots' `check` was computed for. Beside the slots on
    // the process heap (core/ProcessHeap.hpp), so that a fuzz target's
    // restore cannot pair them with slots decoded for other limits.
    // Also the flash write the slots have seen last (flash_written_): a
    // restore takes the board's flash and flash_written_ back, not the
    // slots, and a different value makes run_batch decode every slot again.
    // And the stack floor the translated blocks were made for (their
    // PUSH and POP stop in front of it).
    struct CheckedFor {
        std::uint32_t code_end_minus_one;
        std::uint32_t bad_interrupt_pc;
        std::uint64_t flash_written;
        std::uint16_t stack_floor;
    };
    std::unique_ptr<CheckedFor, FreeDeleter> checked_for_;
    // run_batch does not compare a slot with its flash word (run_one does):
    // whatever writes flash makes the slots there undecoded. An SPM writes
    // through simavr's flash module (avr_flash_ioctl, AVR_IOCTL_FLASH_SPM);
    // this I/O module, first in avr->io_port, sees each SPM ioctl before it
    // (avr_ioctl asks the modules in turn until one answers; this one never
    // does).
    struct FlashWatch {
        avr_io_t io;
        PredecodedCore* core;
    };
    static int on_ioctl(avr_io_t* io, std::uint32_t ctl, void* param);
    void invalidate(avr_flashaddr_t begin, avr_flashaddr_t end);
    // The handler decode_checked gives a slot (a block's head has kBlock).
    static std::uint8_t own_handler(const Slot& s) { return static_cast<std::uint8_t>(s.kind + (s.check ? kKinds : 0)); }
    // Translates the block starting at `pc` (a decoded slot), and the one
    // at the target of the branch or RJMP that ends it or that `pc` holds,
    // where none is there yet.
    void translate_from(avr_flashaddr_t pc);
    // The block starting at `pc`, if its instructions make one: true when
    // the slot now heads it.
    bool translate_block(avr_flashaddr_t pc);
    // The next PC of the instruction at `pc` (+2, +4 or +6 after a skip)
    // is at the crash oracles' limits (decode_checked's test without SP).
    bool next_pc_may_trip(avr_flashaddr_t pc) const;
    // The meter's layout in run_batch: (fuel - 1) from this bit up, the
    // room for instructions below.
    static constexpr int kStepBits = 20;
    // On the process heap, beside the slots whose `target` indexes its
    // blocks; null without translation.
    std::unique_ptr<BlockTranslator> translator_;
    avr_t* avr_;
    FlashWatch flash_watch_{};
    // A value no other write in this process had (a process-wide count):
    // after a restore the board's value matches checked_for_'s only if the
    // slots saw exactly this flash.
    std::uint64_t flash_written_ = 0;
    std::uint64_t handed_ = 0;
    avr_io_read_t port_read_ = nullptr;  // Machine::port_read
};

namespace predecoded_detail {

// The core's view of avr_t: the pointers every instruction uses, read once
// per batch (a store through data[], uint8_t, which may alias anything,
// would otherwise make the compiler reload them after each instruction).
// The rarely used sizes are read from avr_t where needed, so that they do
// not take registers across run_batch's dispatch. Nothing a batch runs
// changes any of them (simavr's I/O callbacks do not either).
struct Machine {
    explicit Machine(avr_t* a) : Machine(a, a->gdb != nullptr) {}
    // `watched` false where the caller has seen that no GDB stub is attached
    // (a constant the compiler folds into every access check).
    Machine(avr_t* a, bool is_watched, avr_io_read_t port_read_callback = nullptr)
        : avr(a), data(a->data), sreg(a->sreg), flash(a->flash), port_read(port_read_callback), watched(is_watched) {}
    avr_t* avr;
    std::uint8_t* data;
    std::uint8_t* sreg;
    const std::uint8_t* flash;
    // simavr's avr_ioport_read, the read callback of every PINx register
    // (find_port_read); null: PIN reads go through the callback.
    avr_io_read_t port_read;
    bool watched;  // simavr's GDB stub is attached (its watchpoints see data accesses)
    std::uint32_t ramend() const { return avr->ramend; }
    std::uint32_t flashend() const { return avr->flashend; }
    int address_size() const { return avr->address_size; }
};

__attribute__((always_inline)) inline std::uint16_t flash16(const std::uint8_t* flash, std::size_t addr) {
#if __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    std::uint16_t word;  // one load: flash is little-endian, like this host
    std::memcpy(&word, flash + addr, sizeof word);
    return word;
#else
    return static_cast<std::uint16_t>(flash[addr] | (flash[addr + 1] << 8));
#endif
}

// _avr_is_instruction_32_bits (sim_core.c).
__attribute__((always_inline)) inline bool is_32_bit(const std::uint8_t* flash, std::size_t pc) {
    const std::uint16_t o = flash16(flash, pc) & 0xfc0f;
    return o == 0x9200 || o == 0x9000 || o == 0x940c || o == 0x940d || o == 0x940e || o == 0x940f;
}

// True when simavr's _avr_set_ram(addr, v) (kWrite) would only store v in
// data[addr], or its _avr_get_ram(addr) only read it: a register, an I/O
// slot with no callback that way and no IRQ (not SREG), or RAM up to
// RAMEND, with no GDB stub watching.
template <bool kWrite>
__attribute__((always_inline)) inline bool plain_access(const Machine& m, std::uint16_t addr) {
    if (addr > m.ramend() || m.watched) return false;
    if (addr < 32 || addr >= MAX_IOs + 31) return true;
    if (addr == R_SREG) return false;
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    return (kWrite ? io.w.c == nullptr : io.r.c == nullptr) && io.irq == nullptr;
}
__attribute__((always_inline)) inline bool plain_write(const Machine& m, std::uint16_t addr) { return plain_access<true>(m, addr); }
__attribute__((always_inline)) inline bool plain_read(const Machine& m, std::uint16_t addr) { return plain_access<false>(m, addr); }

// plain_access for an address past the I/O registers (ioend) within
// RAMEND, as LDS/STS decode it (PredecodedCore::kRamOperand): beyond
// simavr's io[] always plain; inside it, while nothing hooks the byte.
template <bool kWrite>
__attribute__((always_inline)) inline bool plain_ram_operand(const Machine& m, std::uint16_t addr) {
    if (m.watched) return false;
    if (addr >= MAX_IOs + 31) return true;
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    return (kWrite ? io.w.c == nullptr : io.r.c == nullptr) && io.irq == nullptr;
}

// An I/O register this core may read or write itself through simavr's
// callbacks, as _avr_get_ram/_avr_set_r do: not SREG, within RAM, no GDB stub.
__attribute__((always_inline)) inline bool io_callable(const Machine& m, std::uint16_t addr) {
    return addr >= 32 && addr < MAX_IOs + 31 && addr != R_SREG && addr <= m.ramend() && !m.watched;
}

// avr_raise_irq(irq, value). With no hook on the IRQ, simavr 1.6's
// avr_raise_irq_float (sim_irq.c) only stores the value (inverted by
// IRQ_FLAG_NOT) and clears IRQ_FLAG_INIT: its early return for a filtered
// unchanged value changes nothing either, as INIT is then already clear,
// and FLOATING is put back as it was. So that case is done here without
// the call; an IRQ with hooks goes to simavr.
__attribute__((always_inline)) inline void raise_irq(avr_irq_t* irq, std::uint32_t value) {
    if (__builtin_expect(irq->hook == nullptr, 1)) {
        irq->value = (irq->flags & IRQ_FLAG_NOT) ? !value : value;
        irq->flags = static_cast<std::uint8_t>(irq->flags & ~IRQ_FLAG_INIT);
    } else {
        avr_raise_irq(irq, value);
    }
}

// Raises the register's IRQs with `v`: the whole byte, then each bit
// (what _avr_get_ram and _avr_set_r do when avr_iomem_getirq made them).
inline void io_raise(avr_irq_t* irq, std::uint8_t v) {
    raise_irq(irq + AVR_IOMEM_IRQ_ALL, v);
    for (int i = 0; i < 8; i++) raise_irq(irq + i, (v >> i) & 1);
}

// _avr_get_ram(addr) for an io_callable address: the read callback's value
// stored, the IRQs raised, then the byte as avr_core_watch_read returns it.
__attribute__((always_inline)) inline std::uint8_t io_read(const Machine& m, std::uint16_t addr) {
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    if (io.r.c) m.data[addr] = io.r.c(m.avr, addr, io.r.param);
    if (io.irq) io_raise(io.irq, m.data[addr]);
    return m.data[addr];
}

// avr_ioport_read (simavr 1.6, avr_ioport.c), the read callback of a PINx
// register, done here while nothing but the data space can observe it: no
// hook on the port's REG_PIN IRQ and no IRQs made on the register itself
// (io_read's io_raise). Then the callback only stores the pins' value -
// PIN's bits where DDR has an input, PORT's where it has an output - in
// the register, raises REG_PIN with it (raise_irq's inline store) and
// returns it through avr_core_watch_read, which with no GDB stub
// (io_callable) is a read of the byte. Nothing that the checks after a
// callback look at (timers, the core's state, interrupts) changes, so the
// batch goes on as after a plain read. False, with nothing done, where
// the register is not a port's PIN or something observes the read.
__attribute__((always_inline)) inline bool port_pin_read(const Machine& m, std::uint16_t addr, std::uint8_t& value) {
    const auto& io = m.avr->io[AVR_DATA_TO_IO(addr)];
    if (io.r.c != m.port_read || io.r.c == nullptr || io.irq != nullptr) return false;
    const auto* port = static_cast<const avr_ioport_t*>(io.r.param);
    avr_irq_t* const reg_pin = port->io.irq + IOPORT_IRQ_REG_PIN;
    if (reg_pin->hook != nullptr) return false;
    const std::uint8_t ddr = m.data[port->r_ddr];
    const auto v = static_cast<std::uint8_t>((m.data[port->r_pin] & ~ddr) | (m.data[port->r_port] & ddr));
    m.data[addr] = v;
    raise_irq(reg_pin, v);
    value = v;
    return true;
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
    for (int i = 0; i < m.address_size(); i++, ret >>= 8, sp--) m.data[sp] = static_cast<std::uint8_t>(ret);
    set_sp(m.data, sp);
}

// LD/ST's pointer register pair at `low` (X, Y or Z) after its access,
// read again from the registers (not written yet): pre-decremented
// (mode 2) or post-incremented (mode 1), written back high byte first as
// _avr_set_r16le_hl does. The I/O paths use it after a callback, where
// keeping the pointer and the mode across the call cost the plain path
// registers.
inline void step_pointer(std::uint8_t* data, std::uint8_t low, std::uint8_t mode) {
    std::uint16_t p = static_cast<std::uint16_t>((data[low + 1] << 8) | data[low]);
    if (mode == 2) p--;
    if (mode == 1) p++;
    data[low + 1] = static_cast<std::uint8_t>(p >> 8);
    data[low] = static_cast<std::uint8_t>(p);
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
// The flags of ADD/ADC and of SUB/SBC/SUBI/SBCI/CP/CPC/CPI, which
// sim_core.c computes with the datasheet's bit formulas
// (_avr_flags_add_zns, _avr_flags_sub_zns, _avr_flags_sub_Rzns), here from
// the result before it is cut to 8 bits, by the full adder's identities
// (the same function of the operands; core_sweep runs every one of these
// instructions over all operand pairs against avr_run_one):
// - C, the carry (borrow) out of bit 7: bit 8 of the sum (of the two's
//   complement difference, negative exactly when there is a borrow);
// - H, the carry (borrow) out of bit 3: bit 4 of rd ^ rr ^ result, since
//   each result bit is rd ^ rr ^ the carry into it;
// - V: for a sum, both operands' signs differ from the result's; for a
//   difference, the operands' signs differ and the result's differs from rd's.
// `sum` is rd + rr (+ C); `diff` is rd - rr (- C).
__attribute__((always_inline)) inline void flags_add(std::uint8_t* s, std::uint8_t rd, std::uint8_t rr, unsigned sum) {
    const std::uint8_t res = static_cast<std::uint8_t>(sum);
    const std::uint8_t v = static_cast<std::uint8_t>(((rd ^ res) & (rr ^ res)) >> 7);
    const std::uint8_t n = static_cast<std::uint8_t>(res >> 7);
    s[S_H] = static_cast<std::uint8_t>(((rd ^ rr ^ sum) >> 4) & 1);
    s[S_C] = static_cast<std::uint8_t>((sum >> 8) & 1);
    s[S_V] = v;
    s[S_N] = n;
    s[S_Z] = res == 0;
    s[S_S] = n ^ v;
}
// SBC, SBCI and CPC leave Z set only if it was set and the result is zero.
enum ZeroFlag : bool { kSetZ = false, kKeepZ = true };
template <ZeroFlag kZ>
__attribute__((always_inline)) inline void flags_sub(std::uint8_t* s, std::uint8_t rd, std::uint8_t rr, int diff) {
    const unsigned d = static_cast<unsigned>(diff);
    const std::uint8_t res = static_cast<std::uint8_t>(d);
    const std::uint8_t v = static_cast<std::uint8_t>(((rd ^ rr) & (rd ^ res)) >> 7);
    const std::uint8_t n = static_cast<std::uint8_t>(res >> 7);
    s[S_H] = static_cast<std::uint8_t>(((rd ^ rr ^ d) >> 4) & 1);
    s[S_C] = static_cast<std::uint8_t>((d >> 8) & 1);
    s[S_V] = v;
    s[S_N] = n;
    if (kZ == kKeepZ) {
        if (res) s[S_Z] = 0;
    } else {
        s[S_Z] = res == 0;
    }
    s[S_S] = n ^ v;
}

// ADD, ADC, SUB, SBC (and their immediate and compare forms) as one
// operation each, returning the 8-bit result and setting C, Z, N, V, S, H.
#if defined(__x86_64__) && defined(__GNUC__)
// On x86-64 the host's own ADD/ADC/SUB/SBB compute the flags: CF is the
// carry (borrow) out of bit 7, AF out of bit 3, ZF a zero result, SF its
// bit 7 and OF a signed overflow (Intel SDM vol. 1, 3.4.3.1 and appendix
// A) - AVR's C, H, Z, N and V for ADD/ADC/SUB/SBC/CP/CPC (AVR Instruction
// Set Manual, each instruction's "Status Register" equations, which are
// these carries and overflows written as bit formulas; core_sweep checks
// every operand pair against avr_run_one). LAHF puts SF:ZF:0:AF:0:PF:1:CF
// into AH (SDM vol. 2), SETO the overflow; the table turns those nine bits
// into SREG's byte-per-flag form (simavr's avr->sreg[8]: C Z N V S H T I),
// stored as the six bytes C..H - about half the host instructions of the
// bit formulas above.
struct SregBytesFromX86Flags {
    std::uint64_t bytes[512];  // index: OF << 8 | AH after LAHF
    constexpr SregBytesFromX86Flags() : bytes{} {
        for (unsigned index = 0; index < 512; ++index) {
            const std::uint64_t c = index & 1u, z = (index >> 6) & 1u, n = (index >> 7) & 1u;
            const std::uint64_t h = (index >> 4) & 1u, v = (index >> 8) & 1u;
            bytes[index] = c << (8 * S_C) | z << (8 * S_Z) | n << (8 * S_N) | v << (8 * S_V) | (n ^ v) << (8 * S_S) | h << (8 * S_H);
        }
    }
};
inline constexpr SregBytesFromX86Flags kSregBytesFromX86Flags{};

__attribute__((always_inline)) inline void store_sreg_c_to_h(std::uint8_t* s, std::uint32_t ah, std::uint8_t of) {
    const std::uint64_t bytes = kSregBytesFromX86Flags.bytes[(ah & 0xFFu) | (std::uint32_t{of} << 8)];
    const std::uint32_t c_z_n_v = static_cast<std::uint32_t>(bytes);
    const std::uint16_t s_h = static_cast<std::uint16_t>(bytes >> 32);
    static_assert(S_C == 0 && S_Z == 1 && S_N == 2 && S_V == 3 && S_S == 4 && S_H == 5);
    std::memcpy(s, &c_z_n_v, 4);
    std::memcpy(s + 4, &s_h, 2);  // T and I (bytes 6, 7) untouched
}

// kCarryIn: ADC/SBC/SBCI/CPC (the carry from SREG's C).
template <bool kCarryIn>
__attribute__((always_inline)) inline std::uint8_t add8(std::uint8_t* s, std::uint8_t rd, std::uint8_t rr) {
    std::uint8_t res = rd;
    std::uint32_t ax;
    std::uint8_t of;
    if constexpr (kCarryIn) {
        __asm__("btl $0, %k[c]\n\tadcb %[rr], %[res]\n\tlahf\n\tseto %[of]"
                : [res] "+q"(res), "=a"(ax), [of] "=q"(of)
                : [rr] "q"(rr), [c] "r"(std::uint32_t{s[S_C]})
                : "cc");
    } else {
        __asm__("addb %[rr], %[res]\n\tlahf\n\tseto %[of]" : [res] "+q"(res), "=a"(ax), [of] "=q"(of) : [rr] "q"(rr) : "cc");
    }
    store_sreg_c_to_h(s, ax >> 8, of);
    return res;
}
template <bool kCarryIn, ZeroFlag kZ>
__attribute__((always_inline)) inline std::uint8_t sub8(std::uint8_t* s, std::uint8_t rd, std::uint8_t rr) {
    std::uint8_t res = rd;
    std::uint32_t ax;
    std::uint8_t of;
    const std::uint8_t z_before = s[S_Z];
    if constexpr (kCarryIn) {
        __asm__("btl $0, %k[c]\n\tsbbb %[rr], %[res]\n\tlahf\n\tseto %[of]"
                : [res] "+q"(res), "=a"(ax), [of] "=q"(of)
                : [rr] "q"(rr), [c] "r"(std::uint32_t{s[S_C]})
                : "cc");
    } else {
        __asm__("subb %[rr], %[res]\n\tlahf\n\tseto %[of]" : [res] "+q"(res), "=a"(ax), [of] "=q"(of) : [rr] "q"(rr) : "cc");
    }
    store_sreg_c_to_h(s, ax >> 8, of);
    if constexpr (kZ == kKeepZ) s[S_Z] &= z_before;
    return res;
}
#else
template <bool kCarryIn>
__attribute__((always_inline)) inline std::uint8_t add8(std::uint8_t* s, std::uint8_t rd, std::uint8_t rr) {
    const unsigned sum = rd + rr + (kCarryIn ? s[S_C] : 0u);
    flags_add(s, rd, rr, sum);
    return static_cast<std::uint8_t>(sum);
}
template <bool kCarryIn, ZeroFlag kZ>
__attribute__((always_inline)) inline std::uint8_t sub8(std::uint8_t* s, std::uint8_t rd, std::uint8_t rr) {
    const int diff = rd - rr - (kCarryIn ? s[S_C] : 0);
    flags_sub<kZ>(s, rd, rr, diff);
    return static_cast<std::uint8_t>(diff);
}
#endif

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

__attribute__((always_inline)) inline PredecodedCore::Slot* PredecodedCore::slot_at(const predecoded_detail::Machine& m, avr_flashaddr_t pc) {
    Slot* slot = &slots_[pc >> 1];
    const std::uint16_t word = predecoded_detail::flash16(m.flash, pc);
    if (__builtin_expect(slot->word != word || slot->kind == kUndecoded, 0)) {
        *slot = decode_checked(m.avr, word, pc);
        // run_batch meets it as undecoded, decodes it again and may make it
        // a block's head (it looks for blocks where it decodes).
        if (translator_) slot->handler = kUndecoded;
    }
    return slot;
}

__attribute__((always_inline)) inline avr_flashaddr_t PredecodedCore::run_one(avr_t* avr) {
    const avr_flashaddr_t pc = avr->pc;
    if (__builtin_expect(pc < avr->flashend, 1)) {
        const predecoded_detail::Machine m(avr);
        avr_flashaddr_t new_pc;
        int cycles;
        if (__builtin_expect(execute(m, *slot_at(m, pc), pc, avr->cycle, new_pc, cycles) != Done::HandOver, 1)) {
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
    // The handlers' endings (PredecodedOps.inc).
#define AVRBENCH_CYCLE_BEFORE cycle_before
#define AVRBENCH_PC pc
#define AVRBENCH_OP(kind) case kind:
#define AVRBENCH_NEXT() goto plain
#define AVRBENCH_NEXT_CALLED() goto called_simavr
#define AVRBENCH_HAND_OVER() goto hand_over
    // slot_at compared the first word only.
#define AVRBENCH_WORD2_HOLDS() (slot->word2 == flash16(m.flash, new_pc))
    switch (slot->kind) {
#include "mcu/PredecodedOps.inc"
        case kUndecoded:
        case kSimavr:
            goto hand_over;
        default:
            __builtin_unreachable();  // decode() makes no other kind
    }
#undef AVRBENCH_OP
#undef AVRBENCH_CYCLE_BEFORE
#undef AVRBENCH_PC
#undef AVRBENCH_NEXT
#undef AVRBENCH_NEXT_CALLED
#undef AVRBENCH_HAND_OVER
#undef AVRBENCH_WORD2_HOLDS
plain:
    new_pc_out = new_pc;
    cycles_out = cycle;
    return Done::Plain;
called_simavr:
    new_pc_out = new_pc;
    cycles_out = cycle;
    return Done::CalledSimavr;
hand_over:
    return Done::HandOver;
}

}  // namespace avrbench
