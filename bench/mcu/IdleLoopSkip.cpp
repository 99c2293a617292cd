#include "mcu/IdleLoopSkip.hpp"

#include <algorithm>
#include <cstring>

extern "C" {
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_cycle_timers.h>
#include <sim_interrupts.h>
}

namespace avrbench {
namespace {

// Instructions between tries: short after a jump (the loop is likely to be
// entered again once the event is served), doubling while tries fail. On
// code with no idle loop a try watches up to kMaxPassInstructions on the run
// loop's general step: at most every 262 144 instructions that costs about
// 2 % (65 536 cost 7 % on the workload suite's kernels, docs/PERFORMANCE.md).
constexpr std::uint32_t kMinInterval = 64;
constexpr std::uint32_t kMaxInterval = 262144;
// A pass longer than this is not the kind of loop worth watching. The
// longest idle passes seen: grbl 1.1's 185 instructions, Teacup's 104,
// Prusa-Firmware's 64 (the passes the skipper jumped over, counted on
// their runs); a watch that fails costs the general step (about 230 host
// instructions each), and most that failed had watched 1 024 (a start
// outside any loop): 256 took 14 % off a Teacup job.
constexpr std::uint32_t kMaxPassInstructions = 256;
constexpr std::size_t kMaxWrittenBytes = 64;
// After a delay loop, how often and how many instructions apart to look for
// it again before watching other code (an ISR is typically tens of instructions).
constexpr unsigned kDelayLoopGraceLooks = 64;
constexpr std::uint32_t kDelayLoopGraceInterval = 16;
// After a jump, the event that ended it is most often an interrupt, whose
// service routine runs deeper on the stack than the loop (the return
// address and its saved registers): a pass watched there fails at its RETI
// and doubles the back-off, and the loop is found again only after the
// watch of up to kMaxPassInstructions on the general step. Until SP is back
// at the loop's level, look again after this many instructions - or at once
// after a RETI that returns to that level (look_after_interrupt_return),
// where the loop usually comes back -, up to this many times.
// (grbl_stepper during a move: a step interrupt every 2 000 cycles; 20 000
// jumps cost 70 000 host instructions each before, docs/PERFORMANCE.md,
// which has the other settings tried.)
constexpr unsigned kAfterJumpLooks = 8;
constexpr std::uint32_t kAfterJumpInterval = 128;

constexpr std::uint32_t kIoBase = 0x20;

std::uint16_t register_pair(const avr_t* avr, int low) {
    return static_cast<std::uint16_t>(avr->data[low] | (avr->data[low + 1] << 8));
}

std::uint16_t stack_pointer(const avr_t* avr) { return register_pair(avr, R_SPL); }

// Shape of simavr's pending cycle timers: a timer added or moved during a
// watched pass means something had a side effect the data space does not show.
struct TimerShape {
    std::uint64_t first_when = ~0ull;
    unsigned count = 0;
    bool operator==(const TimerShape& o) const { return first_when == o.first_when && count == o.count; }
};

TimerShape timer_shape(const avr_t* avr) {
    TimerShape s;
    const avr_cycle_timer_slot_p first = avr->cycle_timers.timer;
    if (first != nullptr) s.first_when = first->when;
    for (avr_cycle_timer_slot_p t = first; t != nullptr; t = t->next) ++s.count;
    return s;
}

}  // namespace

IdleLoopSkipper::IdleLoopSkipper(avr_t* avr) : avr_(avr), readable_io_(MAX_IOs, false), backoff_(kMinInterval) {
    // UCSRnA's read callback (simavr's avr_uart_status_read) computes the
    // frame-error bit from the receive FIFO and, when the FIFO is empty,
    // raises XON: both only change through the UART's cycle timers and IRQs.
    // The bench clears AVR_UART_FLAG_POLL_SLEEP, the one wall-clock effect
    // (fixes/UartFraming); a USART that still has it stays refused.
    for (avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind == nullptr || std::strcmp(io->kind, "uart") != 0) continue;
        const auto* uart = reinterpret_cast<const avr_uart_t*>(io);
        if (uart->flags & AVR_UART_FLAG_POLL_SLEEP) continue;
        const unsigned address = uart->rxc.raised.reg;
        if (address >= kIoBase && address < kIoBase + MAX_IOs) readable_io_[address - kIoBase] = true;
    }
}

bool IdleLoopSkipper::look_after_interrupt_return(std::uint16_t sp_after) const {
    return !watching_ && after_jump_looks_ < kAfterJumpLooks && sp_after == jump_sp_;
}

std::uint32_t IdleLoopSkipper::give_up() {
    watching_ = false;
    backoff_ = std::min(backoff_ * 2, kMaxInterval);
    return backoff_;
}

std::uint32_t IdleLoopSkipper::start_watching(std::uint64_t run_end_cycle) {
    avr_t* const avr = avr_;
    if (avr->state != cpu_Running || avr->interrupt_state != 0 || avr_has_pending_interrupts(avr)) return give_up();
    switch (skip_delay_loop(run_end_cycle)) {
    case DelayLoop::None:
        // Just left a delay loop: most likely for an interrupt's service
        // routine, and it comes back. Looking in a little while is cheaper
        // than watching the routine pass by instruction by instruction.
        if (in_delay_loop_ && delay_misses_ < kDelayLoopGraceLooks) {
            ++delay_misses_;
            return kDelayLoopGraceInterval;
        }
        in_delay_loop_ = false;
        break;
    case DelayLoop::AtItsBranch:
        return 1;  // the loop's first instruction comes next
    case DelayLoop::Skipped:
    case DelayLoop::EventTooClose:
        // Look again after one pass (two instructions): back at the loop's
        // first instruction, past the event unless it was an interrupt.
        in_delay_loop_ = true;
        delay_misses_ = 0;
        backoff_ = kMinInterval;
        return 2;
    }
    if (after_jump_looks_ < kAfterJumpLooks) {
        ++after_jump_looks_;
        if (stack_pointer(avr) < jump_sp_) return kAfterJumpInterval;
    }
    head_pc_ = avr->pc;
    head_cycle_ = avr->cycle;
    const TimerShape timers = timer_shape(avr);
    timer_cycle_ = timers.first_when;
    timer_count_ = timers.count;
    std::memcpy(registers_, avr->data, sizeof registers_);
    std::memcpy(sreg_, avr->sreg, sizeof sreg_);
    sp_ = stack_pointer(avr);
    written_.clear();
    watching_ = true;
    watched_ = 1;
    if (inspect_next_instruction() == Access::Refuse) return give_up();
    return 1;
}

std::uint32_t IdleLoopSkipper::tick(std::uint64_t run_end_cycle) {
    if (!watching_) return start_watching(run_end_cycle);
    avr_t* const avr = avr_;
    if (avr->state != cpu_Running || avr->interrupt_state != 0) return give_up();
    if (avr->pc == head_pc_ && back_where_it_started()) {
        watching_ = false;
        const std::uint64_t period = avr->cycle - head_cycle_;
        // No timer came due, appeared or moved during the pass (the first is
        // the same and still ahead): the next passes repeat this one exactly
        // up to the boundary before it.
        const TimerShape timers = timer_shape(avr);
        const std::uint64_t limit = std::min(timers.first_when, run_end_cycle);
        if (period == 0 || !(timers == TimerShape{timer_cycle_, timer_count_}) || avr->cycle >= limit) {
            return give_up();
        }
        const std::uint64_t passes = (limit - 1 - avr->cycle) / period;
        if (passes == 0) return give_up();
        avr->cycle += passes * period;
        ++jumps_;
        cycles_skipped_ += passes * period;
        backoff_ = kMinInterval;
        jump_sp_ = sp_;
        after_jump_looks_ = 0;
        return kMinInterval;
    }
    if (++watched_ > kMaxPassInstructions) return give_up();
    if (inspect_next_instruction() == Access::Refuse) return give_up();
    return 1;
}

IdleLoopSkipper::DelayLoop IdleLoopSkipper::skip_delay_loop(std::uint64_t run_end_cycle) {
    // The two-instruction count-down loops of avr-libc's _delay_loop_1/2,
    // Arduino's delayMicroseconds and most hand-written delays (AVR
    // Instruction Set Manual: SBIW 2 cycles, DEC 1, BRNE 2 when taken):
    //   sbiw r24..r30, 1 / brne .-4     4 cycles a pass
    //   dec  Rd          / brne .-4     3 cycles a pass
    // A pass changes only the counter and the flags. Whole passes are added
    // arithmetically; the last one before the next event runs for real, so
    // the flags are the ones that pass computes.
    avr_t* const avr = avr_;
    const std::uint32_t pc = avr->pc;
    if (pc + 3 > avr->flashend) return DelayLoop::None;
    const unsigned op = avr->flash[pc] | (avr->flash[pc + 1] << 8);
    const unsigned next = avr->flash[pc + 2] | (avr->flash[pc + 3] << 8);
    constexpr unsigned kBrneBackTwoWords = 0xF7F1;  // brne .-4: 1111 01kk kkkk k001, k = -2
    const auto counts_down = [](unsigned word) { return (word & 0xFFCF) == 0x9701 || (word & 0xFE0F) == 0x940A; };
    if (op == kBrneBackTwoWords && pc >= 2 && counts_down(avr->flash[pc - 2] | (avr->flash[pc - 1] << 8))) {
        return DelayLoop::AtItsBranch;
    }
    if (next != kBrneBackTwoWords) return DelayLoop::None;
    std::uint32_t count = 0;
    unsigned cycles_per_pass = 0;
    int low = -1;
    bool word = false;
    if ((op & 0xFFCF) == 0x9701) {  // SBIW Rd+1:Rd, 1 (1001 0111 KKdd KKKK, K = 1)
        low = 24 + 2 * ((op >> 4) & 3);
        count = register_pair(avr, low);
        if (count == 0) count = 0x10000;
        cycles_per_pass = 4;
        word = true;
    } else if ((op & 0xFE0F) == 0x940A) {  // DEC Rd (1001 010d dddd 1010)
        low = (op >> 4) & 0x1F;
        count = avr->data[low];
        if (count == 0) count = 0x100;
        cycles_per_pass = 3;
    } else {
        return DelayLoop::None;
    }
    const avr_cycle_timer_slot_p first = avr->cycle_timers.timer;
    const std::uint64_t limit = std::min<std::uint64_t>(first != nullptr ? first->when : ~0ull, run_end_cycle);
    if (avr->cycle >= limit) return DelayLoop::EventTooClose;
    // Passes that come back here: count - 1 (the last falls through), and
    // only as many as end before the next event.
    const std::uint64_t passes = std::min<std::uint64_t>(count - 1, (limit - 1 - avr->cycle) / cycles_per_pass);
    if (passes < 2) return DelayLoop::EventTooClose;
    const std::uint32_t left = count - static_cast<std::uint32_t>(passes - 1);
    avr->data[low] = static_cast<std::uint8_t>(left);
    if (word) avr->data[low + 1] = static_cast<std::uint8_t>(left >> 8);
    avr->cycle += (passes - 1) * cycles_per_pass;
    ++jumps_;
    cycles_skipped_ += (passes - 1) * cycles_per_pass;
    return DelayLoop::Skipped;
}

bool IdleLoopSkipper::back_where_it_started() const {
    const avr_t* const avr = avr_;
    if (std::memcmp(registers_, avr->data, sizeof registers_) != 0) return false;
    if (std::memcmp(sreg_, avr->sreg, sizeof sreg_) != 0) return false;
    if (stack_pointer(avr) != sp_) return false;
    for (const Written& w : written_) {
        if (avr->data[w.address] != w.value_before) return false;
    }
    return true;
}

bool IdleLoopSkipper::note_read(std::uint32_t address) const {
    if (address > avr_->ramend) return false;
    if (address < kIoBase || address >= kIoBase + MAX_IOs) return true;
    const auto& slot = avr_->io[address - kIoBase];
    if (slot.irq != nullptr) return false;  // iomem IRQs: someone watches this register
    return slot.r.c == nullptr || readable_io_[address - kIoBase];
}

bool IdleLoopSkipper::note_write(std::uint32_t address) {
    if (address > avr_->ramend) return false;
    if (address >= kIoBase && address < kIoBase + MAX_IOs) {
        const auto& slot = avr_->io[address - kIoBase];
        // SREG's write hook (fixes/InterruptTiming) only acts while an
        // interrupt waits, which a watched pass never has.
        if (slot.irq != nullptr || (slot.w.c != nullptr && address != R_SREG)) return false;
    }
    // SP changes without a store (PUSH, CALL, RET, POP move it) and is
    // compared as a whole: its value at the first OUT is not its value at the head.
    if (address == R_SPL || address == R_SPH) return true;
    const auto same = [address](const Written& w) { return w.address == address; };
    if (std::find_if(written_.begin(), written_.end(), same) != written_.end()) return true;
    if (written_.size() >= kMaxWrittenBytes) return false;
    written_.push_back({static_cast<std::uint16_t>(address), avr_->data[address]});
    return true;
}

IdleLoopSkipper::Access IdleLoopSkipper::inspect_next_instruction() {
    const avr_t* const avr = avr_;
    const std::uint32_t pc = avr->pc;
    if (pc + 3 > avr->flashend) return Access::Refuse;
    const unsigned op = avr->flash[pc] | (avr->flash[pc + 1] << 8);
    const unsigned next_word = avr->flash[pc + 2] | (avr->flash[pc + 3] << 8);
    const std::uint16_t x = register_pair(avr, 26), y = register_pair(avr, 28), z = register_pair(avr, 30);
    const std::uint16_t sp = stack_pointer(avr);
    const auto ok = [](bool fine) { return fine ? Access::Fine : Access::Refuse; };
    // Encodings from the AVR Instruction Set Manual (Atmel-0856).
    if ((op & 0xFC00) == 0x9000) {  // 1001 00sd dddd xxxx: LDS/STS, LD/ST, LPM, ELPM, PUSH/POP
        const bool store = (op & 0x0200) != 0;
        std::uint32_t address = 0;
        switch (op & 0xF) {
        case 0x0: address = next_word; break;  // LDS/STS k
        case 0x1: address = z; break;           // Z+
        case 0x2: address = static_cast<std::uint16_t>(z - 1); break;
        case 0x9: address = y; break;  // Y+
        case 0xA: address = static_cast<std::uint16_t>(y - 1); break;
        case 0xC: address = x; break;
        case 0xD: address = x; break;
        case 0xE: address = static_cast<std::uint16_t>(x - 1); break;
        case 0xF:  // PUSH writes at SP, POP reads SP + 1
            return ok(store ? note_write(sp) : note_read(static_cast<std::uint16_t>(sp + 1)));
        case 0x4: case 0x5: case 0x6: case 0x7:
            return store ? Access::Refuse : Access::Fine;  // LPM/ELPM read flash; XCH/LAS/LAC/LAT: XMEGA only
        default:
            return Access::Refuse;  // reserved
        }
        return ok(store ? note_write(address) : note_read(address));
    }
    if ((op & 0xD000) == 0x8000) {  // 10q0 qqsd dddd yqqq: LDD/STD Y+q, Z+q (LD/ST Y, Z)
        const unsigned q = ((op >> 8) & 0x20) | ((op >> 7) & 0x18) | (op & 0x7);
        const std::uint32_t address = static_cast<std::uint16_t>(((op & 0x8) ? y : z) + q);
        return ok((op & 0x0200) ? note_write(address) : note_read(address));
    }
    if ((op & 0xF000) == 0xB000) {  // IN 1011 0AAd dddd AAAA, OUT 1011 1AAr rrrr AAAA
        const std::uint32_t address = kIoBase + (((op >> 5) & 0x30) | (op & 0xF));
        return ok((op & 0x0800) ? note_write(address) : note_read(address));
    }
    if ((op & 0xFC00) == 0x9800) {  // CBI 98, SBIC 99, SBI 9A, SBIS 9B: 1001 10xx AAAA Abbb
        const std::uint32_t address = kIoBase + ((op >> 3) & 0x1F);
        const bool writes = (op & 0x0100) == 0;  // CBI, SBI read-modify-write
        return ok(note_read(address) && (!writes || note_write(address)));
    }
    const bool call = (op & 0xFE0E) == 0x940E || (op & 0xF000) == 0xD000 || op == 0x9509 || op == 0x9519;
    if (call) {
        bool fine = true;
        for (unsigned i = 0; i < avr->address_size; ++i) fine = fine && note_write(static_cast<std::uint16_t>(sp - i));
        return ok(fine);
    }
    switch (op) {
    case 0x9508: {  // RET: reads the return address above SP
        bool fine = true;
        for (unsigned i = 1; i <= avr->address_size; ++i) fine = fine && note_read(static_cast<std::uint16_t>(sp + i));
        return ok(fine);
    }
    case 0x9518:  // RETI
    case 0x9588:  // SLEEP
    case 0x9598:  // BREAK
    case 0x95A8:  // WDR (re-arms the watchdog's timer)
    case 0x95E8:  // SPM
    case 0x95F8:  // SPM Z+
        return Access::Refuse;
    default:
        return Access::Fine;  // registers, SREG, branches, LPM
    }
}

}  // namespace avrbench
