#include "mcu/PredecodedCore.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <new>

extern "C" {
#include <avr_flash.h>
}

#include "mcu/BlockTranslator.hpp"
#include "mcu/Mcu.hpp"
#include "core/ProcessHeap.hpp"

namespace avrbench {

namespace {
// The read callback simavr's I/O ports register on their PIN registers
// (avr_ioport_read, static in avr_ioport.c): found through a port, as the
// callback whose parameter is that port. Null on a core without ports.
avr_io_read_t find_port_read(const avr_t* avr) {
    for (const avr_io_t* io = avr->io_port; io != nullptr; io = io->next) {
        if (io->kind == nullptr || std::strcmp(io->kind, "port") != 0) continue;
        const auto* port = reinterpret_cast<const avr_ioport_t*>(io);
        const auto& pin = avr->io[AVR_DATA_TO_IO(port->r_pin)];
        if (pin.r.param == port) return pin.r.c;
    }
    return nullptr;
}
}  // namespace

PredecodedCore::PredecodedCore(avr_t* avr, std::uint32_t code_end_minus_one, std::uint32_t bad_interrupt_pc, bool translate_blocks)
    : avr_(avr) {
    // One slot per flash word; calloc leaves untouched pages unmapped and
    // zero is kUndecoded, so only the code that runs costs memory.
    slot_count_ = static_cast<std::size_t>(avr->flashend) / 2 + 2;
    // A cache of what flash says (run_one checks each slot against its
    // flash word; run_batch counts on every flash write invalidating the
    // slots there, and on flash_written_ after a restore), so a fuzz target
    // that restores its board (core/ProcessHeap.hpp) keeps it on the
    // process's heap: what one input decoded, the next need not decode again.
    const OnProcessHeap cache_outlives_restores;
    slots_.reset(static_cast<Slot*>(std::calloc(slot_count_, sizeof(Slot))));
    checked_for_.reset(static_cast<CheckedFor*>(std::malloc(sizeof(CheckedFor))));
    if (!slots_ || !checked_for_) throw std::bad_alloc();
    if (translate_blocks && BlockTranslator::available()) translator_ = std::make_unique<BlockTranslator>();
    *checked_for_ = CheckedFor{code_end_minus_one, bad_interrupt_pc, flash_written_, 0};
    port_read_ = find_port_read(avr);
    flash_watch_.io.kind = "predecoded-core";
    flash_watch_.io.ioctl = &PredecodedCore::on_ioctl;
    flash_watch_.io.avr = avr;
    flash_watch_.io.next = avr->io_port;
    flash_watch_.core = this;
    avr->io_port = &flash_watch_.io;
}

PredecodedCore::~PredecodedCore() {
    for (avr_io_t** link = &avr_->io_port; *link != nullptr; link = &(*link)->next) {
        if (*link == &flash_watch_.io) {
            *link = flash_watch_.io.next;
            break;
        }
    }
}

int PredecodedCore::on_ioctl(avr_io_t* io, std::uint32_t ctl, void*) {
    if (ctl == AVR_IOCTL_FLASH_SPM) {
        // The page avr_flash_ioctl may erase or write: Z (with RAMPZ) cut
        // down to its page. Pages are 64 to 256 bytes on the AVRs simavr
        // has (SPM_PAGESIZE); 512 covers any of them.
        const avr_t* avr = io->avr;
        avr_flashaddr_t z = avr->data[R_ZL] | (avr->data[R_ZH] << 8);
        if (avr->rampz) z |= static_cast<avr_flashaddr_t>(avr->data[avr->rampz]) << 16;
        constexpr avr_flashaddr_t kPageBytesAtMost = 512;
        const avr_flashaddr_t page = z & ~(kPageBytesAtMost - 1);
        reinterpret_cast<FlashWatch*>(io)->core->invalidate(page, page + kPageBytesAtMost);
    }
    return -1;  // not answered: the flash module does the SPM
}

void PredecodedCore::flash_written(avr_flashaddr_t begin, avr_flashaddr_t end) { invalidate(begin, end); }

std::size_t PredecodedCore::translated_blocks() const { return translator_ ? translator_->blocks() : 0; }
std::uint64_t PredecodedCore::translated_ops() const { return translator_ ? translator_->ops_translated() : 0; }

namespace {
// The kinds a translated block may hold (BlockTranslator::Op), or false.
bool block_op(PredecodedCore::Kind kind, BlockTranslator::Op& op) {
    using K = PredecodedCore;
    using O = BlockTranslator::Op;
    switch (kind) {
        case K::kNop: op = O::kNop; return true;
        case K::kAdd: op = O::kAdd; return true;
        case K::kAdc: op = O::kAdc; return true;
        case K::kSub: op = O::kSub; return true;
        case K::kSbc: op = O::kSbc; return true;
        case K::kCp: op = O::kCp; return true;
        case K::kCpc: op = O::kCpc; return true;
        case K::kCpi: op = O::kCpi; return true;
        case K::kSubi: op = O::kSubi; return true;
        case K::kSbci: op = O::kSbci; return true;
        case K::kAnd: op = O::kAnd; return true;
        case K::kOr: op = O::kOr; return true;
        case K::kEor: op = O::kEor; return true;
        case K::kAndi: op = O::kAndi; return true;
        case K::kOri: op = O::kOri; return true;
        case K::kMov: op = O::kMov; return true;
        case K::kMovw: op = O::kMovw; return true;
        case K::kLdi: op = O::kLdi; return true;
        case K::kInc: op = O::kInc; return true;
        case K::kDec: op = O::kDec; return true;
        case K::kCom: op = O::kCom; return true;
        case K::kNeg: op = O::kNeg; return true;
        case K::kSwap: op = O::kSwap; return true;
        case K::kLsr: op = O::kLsr; return true;
        case K::kAsr: op = O::kAsr; return true;
        case K::kRor: op = O::kRor; return true;
        case K::kMul: op = O::kMul; return true;
        case K::kAdiw: op = O::kAdiw; return true;
        case K::kSbiw: op = O::kSbiw; return true;
        case K::kBst: op = O::kBst; return true;
        case K::kBld: op = O::kBld; return true;
        case K::kSregSet: op = O::kSregSet; return true;
        case K::kSregClear: op = O::kSregClear; return true;
        case K::kLdX: op = O::kLdX; return true;
        case K::kLdY: op = O::kLdY; return true;
        case K::kLdZ: op = O::kLdZ; return true;
        case K::kStX: op = O::kStX; return true;
        case K::kStY: op = O::kStY; return true;
        case K::kStZ: op = O::kStZ; return true;
        case K::kLddY: op = O::kLddY; return true;
        case K::kLddZ: op = O::kLddZ; return true;
        case K::kStdY: op = O::kStdY; return true;
        case K::kStdZ: op = O::kStdZ; return true;
        case K::kLds: op = O::kLds; return true;
        case K::kSts: op = O::kSts; return true;
        case K::kLpm: op = O::kLpm; return true;
        case K::kLpmR0: op = O::kLpm; return true;
        case K::kLpmInc: op = O::kLpmInc; return true;
        case K::kPush: op = O::kPush; return true;
        case K::kPop: op = O::kPop; return true;
        case K::kRcall: op = O::kRcall; return true;
        case K::kCall: op = O::kCall; return true;
        case K::kRet: op = O::kRet; return true;
        case K::kIjmp: op = O::kIjmp; return true;
        case K::kIcall: op = O::kIcall; return true;
        case K::kBrbs: op = O::kBrbs; return true;
        case K::kBrbc: op = O::kBrbc; return true;
        case K::kRjmp: op = O::kRjmp; return true;
        default: return false;
    }
}
}  // namespace

bool PredecodedCore::translate_block(avr_flashaddr_t head) {
    using predecoded_detail::flash16;
    // What the block may take as plain: RAM from past the I/O registers
    // where simavr's io[] (which reaches past ioend on the smaller AVRs)
    // has no callback or IRQ on the byte, as plain_access decides; the
    // callbacks are registered when the board is made (the fixes hook I/O
    // registers only). SP plain as plain_sp decides.
    const avr_t* avr = avr_;
    BlockTranslator::Memory memory{};
    std::uint32_t ram_begin = avr->ioend + 1u;
    for (std::uint32_t addr = ram_begin; addr < MAX_IOs + 31u && addr <= avr->ramend; ++addr) {
        const auto& io = avr->io[AVR_DATA_TO_IO(addr)];
        if (io.r.c != nullptr || io.w.c != nullptr || io.irq != nullptr) ram_begin = addr + 1;
    }
    memory.ram_begin = static_cast<std::uint16_t>(std::min<std::uint32_t>(ram_begin, 0xffff));
    memory.ramend = static_cast<std::uint16_t>(avr->ramend);
    memory.stack_floor = checked_for_->stack_floor;
    const auto& spl = avr->io[AVR_DATA_TO_IO(R_SPL)];
    const auto& sph = avr->io[AVR_DATA_TO_IO(R_SPH)];
    memory.stack_plain = spl.w.c == nullptr && spl.r.c == nullptr && spl.irq == nullptr && sph.w.c == nullptr &&
                         sph.r.c == nullptr && sph.irq == nullptr;
    memory.flashend = avr->flashend;
    memory.flash = avr->flash;
    memory.address_size = avr->address_size;
    memory.code_end_minus_one = checked_for_->code_end_minus_one;
    memory.bad_interrupt_pc = checked_for_->bad_interrupt_pc;
    const auto trips = [&](avr_flashaddr_t next) {
        return next - 1 >= memory.code_end_minus_one || next == memory.bad_interrupt_pc;
    };

    // Long enough for the straight runs compiled C has (the workload
    // suite's average is 2.4-10 instructions); a longer run is two blocks.
    constexpr std::size_t kMostInstructions = 64;
    BlockTranslator::Instruction run[kMostInstructions];
    std::size_t count = 0;
    avr_flashaddr_t pc = head;
    while (count < kMostInstructions && pc < avr->flashend) {
        Slot& s = slots_[pc >> 1];
        if (s.kind == kUndecoded) s = decode_checked(avr, flash16(avr->flash, pc), pc);
        BlockTranslator::Op op;
        if (!block_op(s.kind, op)) break;
        // An instruction after which the crash oracles must look ends the
        // block before it: its next PC at their limits, or SP moved by it
        // (the stores, PUSH and POP the block makes only on plain RAM, at
        // or above the stack floor, so only their PC counts).
        // Calls and returns: their SP in the block's range checks, a static
        // target checked here, a run-time one in the code.
        using O = BlockTranslator::Op;
        const bool stack_op = op == O::kPush || op == O::kPop || op == O::kRcall || op == O::kCall || op == O::kRet || op == O::kIcall;
        const bool jump_checked_here = op == O::kRcall || op == O::kCall || op == O::kRet || op == O::kIjmp || op == O::kIcall;
        const bool only_sp_checked = (s.flags & kMovesSp) != 0 && !next_pc_may_trip(pc);
        if (s.check != 0 && !only_sp_checked && !jump_checked_here) break;
        if (stack_op && !memory.stack_plain) break;
        std::uint32_t target = s.target;
        if (op == O::kCall) {
            if (pc + 3 > avr->flashend) break;  // no second word: avr_run_one's
            target = ((static_cast<avr_flashaddr_t>(s.c) << 16) | flash16(avr->flash, pc + 2)) << 1;
        }
        if ((op == O::kRcall || op == O::kCall) && trips(target)) break;
        if ((op == BlockTranslator::Op::kLds || op == BlockTranslator::Op::kSts) &&
            (s.target < memory.ram_begin || s.target > memory.ramend)) {
            break;
        }
        BlockTranslator::Instruction in{op, s.a, s.b, target};
        // SregSet/SregClear carry their bit in b; LPM into R0 has Rd 0.
        if (s.kind == kSregSet || s.kind == kSregClear) in.a = s.b;
        if (s.kind == kLpmR0) in.a = 0;
        run[count++] = in;
        pc += 2u * static_cast<unsigned>(BlockTranslator::words_of(op));
        if (BlockTranslator::ends_block(op)) break;
    }
    // One instruction alone gains nothing over its handler. The head's
    // `target` becomes the block's index: not an LDS or STS, whose
    // handler (run when the fuel does not cover the block) reads its
    // address there.
    if (count < 2 || BlockTranslator::ends_block(run[0].op) || run[0].op == BlockTranslator::Op::kLds ||
        run[0].op == BlockTranslator::Op::kSts) {
        return false;
    }
    const int index = translator_->translate(run, count, head, memory, kStepBits);
    if (index < 0) return false;
    Slot& first = slots_[head >> 1];
    first.handler = kBlock;
    first.target = static_cast<std::uint32_t>(index);
    return true;
}

void PredecodedCore::translate_from(avr_flashaddr_t pc) {
    if (!translator_) return;
    // A loop's head is the target of the branch at its end, usually not the
    // first instruction the dispatch met (the block that got there first
    // ran through it): it gets a block of its own (translate_block decodes
    // what it needs).
    const auto translate_target = [&](const Slot& s) {
        if (s.kind != kBrbs && s.kind != kBrbc && s.kind != kRjmp && s.kind != kRcall) return;
        const avr_flashaddr_t target = s.target;
        if (target < avr_->flashend && (target & 1) == 0 && target != pc && slots_[target >> 1].handler != kBlock) {
            translate_block(target);
        }
    };
    const Slot& at = slots_[pc >> 1];
    if (at.kind == kBrbs || at.kind == kBrbc || at.kind == kRjmp || at.kind == kRcall) {
        translate_target(at);
        return;
    }
    if (!translate_block(pc)) return;
    const BlockTranslator::Block& block = translator_->block(slots_[pc >> 1].target);
    translate_target(slots_[(block.end - 2) >> 1]);  // the branch that ends it, if one does
}

void PredecodedCore::invalidate(avr_flashaddr_t begin, avr_flashaddr_t end) {
    static std::atomic<std::uint64_t> writes_in_process{0};
    flash_written_ = ++writes_in_process;
    checked_for_->flash_written = flash_written_;
    // From the word before: an LDS or STS there holds the next word.
    const std::size_t first = begin >= 2 ? (begin - 2) / 2 : 0;
    const std::size_t last = std::min<std::size_t>((static_cast<std::size_t>(end) + 1) / 2, slot_count_);
    if (first < last) std::memset(static_cast<void*>(slots_.get() + first), 0, (last - first) * sizeof(Slot));
    // A block that began before the write and ran into it is no longer
    // entered: its first slot runs as the instruction it is.
    if (translator_) {
        for (std::size_t i = 0; i < translator_->blocks(); ++i) {
            const BlockTranslator::Block& block = translator_->block(i);
            Slot& head = slots_[block.head >> 1];
            if (block.head < end && block.end > begin && head.handler == kBlock && head.target == i) head.handler = own_handler(head);
        }
    }
}

PredecodedCore::Slot PredecodedCore::decode_checked(const avr_t* avr, std::uint16_t word, avr_flashaddr_t pc) const {
    Slot s = decode(avr, word, pc);
    // run_batch tests the crash oracles (Mcu::check_after_step: PC 0 or
    // past the code, __bad_interrupt, SP below .bss) only after the
    // instructions that can trip them: those that may move SP, those whose
    // next PC is computed at run time (IJMP, ICALL, RET, and JMP, whose
    // target word is read when it runs), and those whose next PC can be one
    // of the limits: pc + 2, + 4 or + 6 (a skip over a two-word
    // instruction), or the branch target.
    const CheckedFor& limits = *checked_for_;
    const auto trips = [&](avr_flashaddr_t next) { return next - 1 >= limits.code_end_minus_one || next == limits.bad_interrupt_pc; };
    bool check = (s.flags & kMovesSp) || next_pc_may_trip(pc);
    switch (s.kind) {
        case kIjmp: case kIcall: case kEijmp: case kEicall: case kRet: case kJmp: case kCall:
            check = true;
            break;
        case kRjmp: case kRcall: case kBrbs: case kBrbc:
            check = check || trips(s.target);
            break;
        default:
            break;
    }
    s.check = check ? 1 : 0;
    s.handler = static_cast<std::uint8_t>(s.kind + (check ? kKinds : 0));
    return s;
}

bool PredecodedCore::next_pc_may_trip(avr_flashaddr_t pc) const {
    const CheckedFor& limits = *checked_for_;
    const auto trips = [&](avr_flashaddr_t next) { return next - 1 >= limits.code_end_minus_one || next == limits.bad_interrupt_pc; };
    return trips(pc + 2) || trips(pc + 4) || trips(pc + 6);
}

// The dispatch tree of simavr 1.6's avr_run_one (sim_core.c), in its order,
// so that every opcode lands where simavr's switch sends it; the leaves this
// core does not execute itself are kSimavr.
PredecodedCore::Slot PredecodedCore::decode(const avr_t* avr, std::uint16_t opcode, avr_flashaddr_t pc) {
    Slot s{};
    s.word = opcode;
    s.kind = kSimavr;
    const auto d5 = [&] { return static_cast<std::uint8_t>((opcode >> 4) & 0x1f); };
    const auto r5 = [&] { return static_cast<std::uint8_t>(((opcode >> 5) & 0x10) | (opcode & 0xf)); };
    const auto set = [&](Kind kind, unsigned a, unsigned b) {
        s.kind = kind;
        s.a = static_cast<std::uint8_t>(a);
        s.b = static_cast<std::uint8_t>(b);
    };
    const avr_flashaddr_t next_pc = pc + 2;
    switch (opcode & 0xf000) {
        case 0x0000:
            if (opcode == 0x0000) {
                s.kind = kNop;
                break;
            }
            switch (opcode & 0xfc00) {
                case 0x0400: set(kCpc, d5(), r5()); break;
                case 0x0c00: set(kAdd, d5(), r5()); break;
                case 0x0800: set(kSbc, d5(), r5()); break;
                default:
                    switch (opcode & 0xff00) {
                        case 0x0100: set(kMovw, ((opcode >> 4) & 0xf) << 1, (opcode & 0xf) << 1); break;
                        case 0x0200: set(kMuls, 16 + ((opcode >> 4) & 0xf), 16 + (opcode & 0xf)); break;
                        case 0x0300: {
                            const unsigned d = 16 + ((opcode >> 4) & 0x7), r = 16 + (opcode & 0x7);
                            switch (opcode & 0x88) {
                                case 0x00: set(kMulsu, d, r); break;
                                case 0x08: set(kFmul, d, r); break;
                                case 0x80: set(kFmuls, d, r); break;
                                default: set(kFmulsu, d, r); break;
                            }
                        } break;
                        default: break;  // invalid
                    }
            }
            break;
        case 0x1000:
            switch (opcode & 0xfc00) {
                case 0x1800: set(kSub, d5(), r5()); break;
                case 0x1000: set(kCpse, d5(), r5()); break;
                case 0x1400: set(kCp, d5(), r5()); break;
                case 0x1c00: set(kAdc, d5(), r5()); break;
                default: break;
            }
            break;
        case 0x2000:
            switch (opcode & 0xfc00) {
                case 0x2000: set(kAnd, d5(), r5()); break;
                case 0x2400: set(kEor, d5(), r5()); break;
                case 0x2800: set(kOr, d5(), r5()); break;
                case 0x2c00: set(kMov, d5(), r5()); break;
                default: break;
            }
            break;
        case 0x3000: case 0x4000: case 0x5000: case 0x6000: case 0x7000: {
            const unsigned h = 16 + ((opcode >> 4) & 0xf);
            const unsigned k = ((opcode & 0x0f00) >> 4) | (opcode & 0xf);
            const Kind kinds[] = {kCpi, kSbci, kSubi, kOri, kAndi};
            set(kinds[((opcode & 0xf000) >> 12) - 3], h, k);
        } break;
        case 0xa000:
        case 0x8000: {
            const unsigned q = ((opcode & 0x2000) >> 8) | ((opcode & 0x0c00) >> 7) | (opcode & 0x7);
            const bool store = (opcode & 0x0200) != 0;
            switch (opcode & 0xd008) {
                case 0xa000: case 0x8000: set(store ? kStdZ : kLddZ, d5(), q); break;
                case 0xa008: case 0x8008: set(store ? kStdY : kLddY, d5(), q); break;
                default: break;
            }
        } break;
        case 0x9000:
            if ((opcode & 0xff0f) == 0x9408) {
                const unsigned bit = (opcode >> 4) & 7;
                if (bit != S_I)
                    set((opcode & 0x0080) ? kSregClear : kSregSet, 0, bit);
                else
                    s.kind = (opcode & 0x0080) ? kCli : kSei;
                break;
            }
            switch (opcode) {
                case 0x9588:  // SLEEP
                case 0x9598:  // BREAK
                case 0x95a8:  // WDR
                case 0x95e8:  // SPM
                case 0x9518:  // RETI
                    break;
                case 0x9409: s.kind = kIjmp; break;
                case 0x9419: s.kind = kEijmp; break;
                case 0x9519: s.kind = kEicall; break;
                case 0x95d8: set(kElpm, 0, 0); break;  // ELPM (R0 <- (RAMPZ:Z))
                case 0x9509: s.kind = kIcall; break;
                case 0x9508: s.kind = kRet; break;
                case 0x95c8: s.kind = kLpmR0; break;
                default:
                    switch (opcode & 0xfe0f) {
                        case 0x9000: set(kLds, d5(), 0); break;
                        case 0x9004: set(kLpm, d5(), 0); break;
                        case 0x9005: set(kLpmInc, d5(), 0); break;
                        case 0x9006: case 0x9007: set(kElpm, d5(), opcode & 1); break;  // ELPM Rd, Z / Z+
                        case 0x900c: case 0x900d: case 0x900e: set(kLdX, d5(), opcode & 3); break;
                        case 0x920c: case 0x920d: case 0x920e: set(kStX, d5(), opcode & 3); break;
                        case 0x9009: case 0x900a: set(kLdY, d5(), opcode & 3); break;
                        case 0x9209: case 0x920a: set(kStY, d5(), opcode & 3); break;
                        case 0x9200: set(kSts, d5(), 0); break;
                        case 0x9001: case 0x9002: set(kLdZ, d5(), opcode & 3); break;
                        case 0x9201: case 0x9202: set(kStZ, d5(), opcode & 3); break;
                        case 0x900f: set(kPop, d5(), 0); break;
                        case 0x920f: set(kPush, d5(), 0); break;
                        case 0x9400: set(kCom, d5(), 0); break;
                        case 0x9401: set(kNeg, d5(), 0); break;
                        case 0x9402: set(kSwap, d5(), 0); break;
                        case 0x9403: set(kInc, d5(), 0); break;
                        case 0x9405: set(kAsr, d5(), 0); break;
                        case 0x9406: set(kLsr, d5(), 0); break;
                        case 0x9407: set(kRor, d5(), 0); break;
                        case 0x940a: set(kDec, d5(), 0); break;
                        case 0x940c: case 0x940d:
                            s.kind = kJmp;
                            s.c = static_cast<std::uint8_t>(((opcode & 0x01f0) >> 3) | (opcode & 1));
                            break;
                        case 0x940e: case 0x940f:
                            s.kind = kCall;
                            s.c = static_cast<std::uint8_t>(((opcode & 0x01f0) >> 3) | (opcode & 1));
                            break;
                        default:
                            switch (opcode & 0xff00) {
                                case 0x9600: case 0x9700: {
                                    const unsigned p = 24 + ((opcode >> 3) & 0x6);
                                    const unsigned k = ((opcode & 0x00c0) >> 2) | (opcode & 0xf);
                                    set((opcode & 0xff00) == 0x9600 ? kAdiw : kSbiw, p, k);
                                } break;
                                case 0x9800: case 0x9a00: {
                                    const unsigned io = ((opcode >> 3) & 0x1f) + 32;
                                    set((opcode & 0xff00) == 0x9800 ? kCbi : kSbi, io, 1u << (opcode & 0x7));
                                } break;
                                case 0x9900: case 0x9b00: {
                                    const unsigned io = ((opcode >> 3) & 0x1f) + 32;
                                    set((opcode & 0xff00) == 0x9900 ? kSbic : kSbis, io, 1u << (opcode & 0x7));
                                } break;
                                default:
                                    if ((opcode & 0xfc00) == 0x9c00) set(kMul, d5(), r5());
                                    break;
                            }
                    }
            }
            break;
        case 0xb000: {
            const unsigned A = ((((opcode >> 9) & 3) << 4) | (opcode & 0xf)) + 32;
            switch (opcode & 0xf800) {
                case 0xb800: set(kOut, A, d5()); break;
                case 0xb000: set(kIn, d5(), A); break;
                default: break;
            }
        } break;
        case 0xc000:
        case 0xd000: {
            const std::int16_t o = static_cast<std::int16_t>(static_cast<std::int16_t>((opcode << 4) & 0xffff) >> 3);
            s.kind = (opcode & 0xf000) == 0xc000 ? kRjmp : kRcall;
            s.target = (next_pc + o) % (avr->flashend + 1);
        } break;
        case 0xe000: set(kLdi, 16 + ((opcode >> 4) & 0xf), ((opcode & 0x0f00) >> 4) | (opcode & 0xf)); break;
        case 0xf000:
            switch (opcode & 0xfe00) {
                case 0xf000: case 0xf200: case 0xf400: case 0xf600: {
                    // simavr's `case 0xf100` (its flash-overflow opcode 0xF1F1)
                    // can never match under this mask: 0xF1F1 is a branch.
                    const std::int16_t o = static_cast<std::int16_t>(static_cast<std::int16_t>(static_cast<std::uint32_t>(opcode) << 6) >> 9);
                    const bool if_set = (opcode & 0x0400) == 0;
                    set(if_set ? kBrbs : kBrbc, 0, opcode & 7);
                    s.target = next_pc + (o << 1);
                } break;
                case 0xf800: case 0xf900: set(kBld, d5(), opcode & 7); break;
                case 0xfa00: case 0xfb00: set(kBst, d5(), opcode & 7); break;
                case 0xfc00: case 0xfe00: set((opcode & 0x0200) ? kSbrs : kSbrc, d5(), opcode & 7); break;
                default: break;
            }
            break;
        default: break;
    }
    if ((s.kind == kLds || s.kind == kSts) && next_pc + 1 > avr->flashend) s.kind = kSimavr;  // no address word in flash
    if (moves_sp(s.kind)) s.flags |= kMovesSp;
    if (s.kind == kLds || s.kind == kSts) {
        // The address word, for the handlers' fast path while flash holds
        // it: RAM past the I/O registers, up to RAMEND (no SREG, no
        // register file; simavr's io[] still covers its first bytes, whose
        // callbacks and IRQs the handler looks at).
        s.word2 = static_cast<std::uint16_t>(avr->flash[next_pc] | (avr->flash[next_pc + 1] << 8));
        s.target = s.word2;
        if (s.word2 > avr->ioend && s.word2 <= avr->ramend) s.flags |= kRamOperand;
    }
    // STS and OUT store to SPL/SPH only when that is their (decoded) address.
    if ((s.kind == kSts && s.word2 != R_SPL && s.word2 != R_SPH) || (s.kind == kOut && s.a != R_SPL && s.a != R_SPH)) {
        s.flags &= static_cast<std::uint8_t>(~kMovesSp);
    }
    return s;
}

// Threaded code: every handler of PredecodedOps.inc ends in its own copy of
// the checks after an instruction and of the next instruction's dispatch
// (with this instruction's cycle count folded in as a constant; the
// compiler may still share identical tails), instead of one switch in a
// loop with the bounds check, the Done result and the checks of every
// kind behind it. On busy_poll that took the batch from 82 to 47 host
// instructions per AVR instruction, together with the slot's `check` and
// the LDS/STS address decoded once (docs/PERFORMANCE.md).
// Labels as values are a GNU extension (GCC and clang).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
// GCC's SLP vectoriser (-O3) packs a handler's SREG flag bytes into one
// 32-bit store, built with shifts and ORs and a spilled SETcc: more host
// instructions than the byte stores (busy_poll: 47.6 per AVR instruction
// with it, 46.5 without; docs/PERFORMANCE.md).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC push_options
#pragma GCC optimize("no-tree-slp-vectorize")
#endif
template <bool kCover>
PredecodedCore::Batch PredecodedCore::run_batch(avr_t* avr, const BatchLimits& limits, PcEdgeMap* edges) {
    using namespace predecoded_detail;
    Batch batch;
    // simavr's GDB stub watches data accesses: run_one (the general step)
    // hands each of them to avr_run_one.
    if (avr->gdb != nullptr) return batch;
    const Machine m(avr, false, port_read_);
    // With SP already below the floor (a half-written SP, which the oracle
    // lets pass) every step needs the oracle: the general step takes them.
    if (sp_of(m.data) < limits.stack_floor) return batch;
    // A PC past the flash is avr_run_one's (it crashes the core). Inside the
    // loop the PC stays below the code's end (the check after every
    // instruction that can leave it), which is within the flash.
    // (A PC is even: every new PC is a word address times 2; the slot of
    // byte address pc is at byte offset pc * 8.)
    if (avr->pc >= m.flashend() || (avr->pc & 1) != 0 || limits.code_end_minus_one > m.flashend()) return batch;
    if (limits.max_steps == 0) {
        batch.ended = Ended::Count;
        return batch;
    }
    if (checked_for_->code_end_minus_one != limits.code_end_minus_one || checked_for_->bad_interrupt_pc != limits.bad_interrupt_pc ||
        checked_for_->flash_written != flash_written_ || checked_for_->stack_floor != limits.stack_floor) {
        // Other oracle limits (a boot loader wrote another application):
        // every slot is decoded again, with its `check` for these. Or a
        // fuzz target restored its board: the slots may hold what an input
        // wrote to flash.
        std::memset(static_cast<void*>(slots_.get()), 0, slot_count_ * sizeof(Slot));
        *checked_for_ = CheckedFor{limits.code_end_minus_one, limits.bad_interrupt_pc, flash_written_, limits.stack_floor};
        if (translator_) translator_->forget_all();
    }
    // Each handler twice: as is, and (from kKinds on) a copy that tests the
    // crash oracles after it - the slot's `handler` picks one, so the
    // dispatch after the many slots that cannot trip them (`check` 0) tests
    // nothing.
    static const void* const kHandlers[2 * kKinds] = {
#define AVRBENCH_HANDLER_ADDRESS(kind) &&op_##kind,
        AVRBENCH_PREDECODED_KINDS(AVRBENCH_HANDLER_ADDRESS)
#undef AVRBENCH_HANDLER_ADDRESS
#define AVRBENCH_HANDLER_ADDRESS(kind) &&checked_##kind,
        AVRBENCH_PREDECODED_KINDS(AVRBENCH_HANDLER_ADDRESS)
#undef AVRBENCH_HANDLER_ADDRESS
    };
    Slot* const slots = slots_.get();
    std::uint8_t* const data = m.data;
    std::uint8_t* const sreg = m.sreg;
    // What only the paths off the dispatch read - the oracles' limits, the
    // step limit, the core - is kept in memory (volatile: GCC held `this`,
    // `limits` and max_steps in three of the six callee-saved registers
    // and so kept the fuel, the slot and the tables on the stack).
    struct Cold {
        PredecodedCore* core;
        std::uint32_t max_steps;
        std::uint32_t code_end_minus_one;
        std::uint32_t bad_interrupt_pc;
        std::uint16_t stack_floor;
        avr_cycle_count_t horizon;
    };
    volatile Cold cold{this, limits.max_steps, limits.code_end_minus_one, limits.bad_interrupt_pc, limits.stack_floor, limits.horizon};
    // The PC and the cycle count live in registers until the batch ends;
    // AVRBENCH_BEFORE_CALLBACKS stores them before simavr's I/O callbacks.
    // One PC: `new_pc` is, at the dispatch, the instruction to fetch, and
    // in its handler where it goes next; its own PC, wanted only on the way
    // out and before callbacks, follows from the slot's address (slot_pc).
    // The count is kept as the cycles left to the first timer, counted
    // down, with the step limit folded into the same countdown: `fuel` is
    // that budget, or less where max_steps is smaller - every instruction
    // takes at least one cycle, so running out of it never passes
    // max_steps -, with the rest held back in `reserve` (budget = fuel +
    // reserve). When the fuel is out but not the budget, the batch ends
    // with Ended::Count, perhaps before max_steps, and Mcu::run_until runs
    // another.
    // The fuel and the instructions run since the last refuel share one
    // 64-bit counter, `meter`: (fuel - 1) in the bits from kStepBits up, the
    // room for instructions left in the bits below, so that an instruction
    // of c cycles is one subtraction of the constant (c << kStepBits) + 1
    // and the fuel is out exactly when the meter goes negative (one SUB and
    // one JS on x86-64, where a separate step count took an ADD and a TEST
    // more). The fuel is never more than the room (kStepRoom), and every
    // instruction takes a cycle at least, so the room never borrows from
    // the fuel.
    // (64-bit: it indexes the slots and flash with no zero-extension first.)
    std::size_t new_pc = avr->pc;
    avr_cycle_count_t cycle_limit = limits.cycle;
    constexpr std::int64_t kStepRoom = (std::int64_t{1} << kStepBits) - 1;
    std::uint32_t steps = 0;  // up to the last refuel
    std::int64_t meter;
    std::int64_t reserve;
    const auto fuel_left = [&] { return (meter >> kStepBits) + 1; };
    const auto bank_steps = [&] { steps += static_cast<std::uint32_t>(kStepRoom - (meter & kStepRoom)); };
    const auto refuel = [&](std::int64_t budget) {
        const std::int64_t steps_left = cold.max_steps - steps;
        const std::int64_t fuel_cap = steps_left < kStepRoom ? steps_left : kStepRoom;
        reserve = budget > fuel_cap ? budget - fuel_cap : 0;
        meter = ((budget - reserve - 1) * (std::int64_t{1} << kStepBits)) + kStepRoom;
    };
    refuel(static_cast<std::int64_t>(cycle_limit - avr->cycle));
    const Slot* slot;
    // The slot of byte address pc is at byte offset pc * 8.
    const auto slot_pc = [&] {
        return static_cast<avr_flashaddr_t>((reinterpret_cast<const char*>(slot) - reinterpret_cast<const char*>(slots)) / 8);
    };
    int cycle;

#define AVRBENCH_DISPATCH()                                                                       \
    do {                                                                                          \
        slot = reinterpret_cast<const Slot*>(reinterpret_cast<const char*>(slots) + new_pc * 8); \
        new_pc += 2;                                                                              \
        cycle = 1;                                                                                \
        goto* kHandlers[slot->handler];                                                           \
    } while (0)
    // What Mcu::run_until's fast path checks after an instruction, then the
    // next one: the first cycle timer due or the step count (the fuel), and
    // in the handlers' checked copy the crash oracles.
#define AVRBENCH_NEXT()                                                                           \
    do {                                                                                          \
        meter -= (static_cast<std::int64_t>(cycle) << kStepBits) + 1;                             \
        if (__builtin_expect(meter < 0, 0)) goto out_of_fuel;                                     \
        if constexpr (AVRBENCH_CHECKED) goto check_oracles;                                       \
        if constexpr (kCover) edges->hit(static_cast<std::uint32_t>(new_pc));                     \
        AVRBENCH_DISPATCH();                                                                      \
    } while (0)
#define AVRBENCH_NEXT_CALLED() goto after_callbacks
#define AVRBENCH_CYCLE_BEFORE (cycle_limit - static_cast<avr_cycle_count_t>(fuel_left() + reserve))
#define AVRBENCH_PC slot_pc()
#define AVRBENCH_HAND_OVER() goto hand_over
    // Every flash write invalidates the slot before the word it writes.
#define AVRBENCH_WORD2_HOLDS() true
    // Each handler is a block with the slot's operands; it begins by
    // closing the one before (which never falls through: every handler
    // ends in a jump), so they are not live across the dispatch.
#define AVRBENCH_OP(kind)                                    \
    }                                                        \
    op_##kind : {                                            \
        [[maybe_unused]] const std::uint8_t a = slot->a;     \
        [[maybe_unused]] const std::uint8_t b = slot->b;

    AVRBENCH_DISPATCH();
#define AVRBENCH_CHECKED false
    {
#include "mcu/PredecodedOps.inc"
    }
#undef AVRBENCH_CHECKED
#undef AVRBENCH_OP
#define AVRBENCH_OP(kind)                                    \
    }                                                        \
    checked_##kind : {                                       \
        [[maybe_unused]] const std::uint8_t a = slot->a;     \
        [[maybe_unused]] const std::uint8_t b = slot->b;
#define AVRBENCH_CHECKED true
    {
#include "mcu/PredecodedOps.inc"
    }
#undef AVRBENCH_CHECKED
op_kUndecoded:  // a slot not decoded yet (calloc'd, or invalidated by a flash write)
checked_kUndecoded:
{
    // new_pc already past it: the slot's own PC.
    const avr_flashaddr_t pc = slot_pc();
    slots[pc >> 1] = cold.core->decode_checked(avr, flash16(m.flash, pc), pc);  // `slot` points at it
    if constexpr (!kCover) cold.core->translate_from(pc);
    new_pc = pc + 2;
    cycle = 1;
    goto* kHandlers[slot->handler];
}
op_kBlock:  // the head of a translated block (mcu/BlockTranslator.hpp)
checked_kBlock: {
    // Fuzzing counts every instruction's edge: one at a time. The block's
    // first instruction is its slot's kind; it never needs the oracles.
    if constexpr (kCover) goto* kHandlers[own_handler(*slot)];
    const BlockTranslator::Block* const blocks = cold.core->translator_->block_array();
    const BlockTranslator::Block* block = &blocks[slot->target];
    // Entered only when the fuel covers all of it (else its instructions
    // run one by one, and the batch ends after the one that empties the
    // fuel, as without blocks); the code charges the meter for what it ran.
    if (__builtin_expect(meter < block->max_charge, 0)) goto* kHandlers[own_handler(*slot)];
    BlockTranslator::Exit exit = block->code(data, sreg);
    // It ran nothing: its first instruction is the interpreter's (an
    // access that is not plain RAM, say).
    if (__builtin_expect(exit.charge == 0, 0)) goto* kHandlers[own_handler(*slot)];
    // Where the next instruction heads a block the fuel covers, that block
    // runs straight away: a loop of blocks (a division's) goes round here
    // without the dispatch in between. One that runs nothing goes back to
    // the dispatch, which meets it again as above.
    for (;;) {
        meter -= static_cast<std::int64_t>(exit.charge);
        new_pc = exit.pc;
        const Slot* const next = reinterpret_cast<const Slot*>(reinterpret_cast<const char*>(slots) + new_pc * 8);
        if (next->handler != kBlock) break;
        block = &blocks[next->target];
        if (meter < block->max_charge) break;
        exit = block->code(data, sreg);
        if (exit.charge == 0) break;
    }
    AVRBENCH_DISPATCH();
}
op_kSimavr:
checked_kSimavr:
hand_over:
    batch.ended = Ended::HandOver;
    avr->pc = slot_pc();
    goto out;
after_callbacks : {
    bank_steps();
    ++steps;
    // A callback may move the cycle count itself (fixes/EepromTiming
    // halts the core 4 cycles on a read that way): count on from it.
    const avr_cycle_count_t cycle_now = avr->cycle + static_cast<avr_cycle_count_t>(cycle);
    avr->cycle = cycle_now;
    cycle_limit = cycle_now;
    meter = -1;  // no fuel, no instruction since the banking
    reserve = 0;
    // What the fast path checks after avr_run_one: a timer the callbacks
    // made due, a core no longer running, an interrupt on its way.
    const avr_cycle_timer_slot_p first = avr->cycle_timers.timer;
    const avr_cycle_count_t horizon = cold.horizon;
    const avr_cycle_count_t next_limit = first != nullptr && first->when < horizon ? first->when : horizon;
    if (next_limit <= cycle_now || avr->state != cpu_Running || avr->interrupt_state != 0) goto timer_due;
    cycle_limit = next_limit;
    refuel(static_cast<std::int64_t>(cycle_limit - cycle_now));
    if (slot->check == 0) goto advance;
    goto check_oracles;
}
out_of_fuel:
    if (fuel_left() + reserve <= 0) goto timer_due;
    // Only the step limit's share is out: this instruction ends the batch.
    if (slot->check == 0) goto advance;
check_oracles:
    // SP only changes through the kinds that may store to the data space.
    if (new_pc - 1 >= cold.code_end_minus_one || new_pc == cold.bad_interrupt_pc ||
        ((slot->flags & kMovesSp) && sp_of(data) < cold.stack_floor)) {
        batch.ended = Ended::CheckPc;
        batch.new_pc = static_cast<avr_flashaddr_t>(new_pc);
        avr->pc = slot_pc();
        goto out;
    }
advance:
    if constexpr (kCover) edges->hit(static_cast<std::uint32_t>(new_pc));
    if (meter < 0) {  // no fuel left
        batch.ended = Ended::Count;
        avr->pc = static_cast<avr_flashaddr_t>(new_pc);
        goto out;
    }
    AVRBENCH_DISPATCH();
timer_due:
    // avr->pc stays at the last instruction; Mcu finishes it (SimavrStepper::finish).
    batch.ended = Ended::TimerDue;
    batch.new_pc = static_cast<avr_flashaddr_t>(new_pc);
    avr->pc = slot_pc();
out:
#undef AVRBENCH_OP
#undef AVRBENCH_CYCLE_BEFORE
#undef AVRBENCH_PC
#undef AVRBENCH_HAND_OVER
#undef AVRBENCH_WORD2_HOLDS
#undef AVRBENCH_NEXT_CALLED
#undef AVRBENCH_NEXT
#undef AVRBENCH_DISPATCH
    bank_steps();
    batch.steps = steps;
    avr->cycle = cycle_limit - static_cast<avr_cycle_count_t>(fuel_left() + reserve);
    return batch;
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#endif
#pragma GCC diagnostic pop

template PredecodedCore::Batch PredecodedCore::run_batch<false>(avr_t*, const BatchLimits&, PcEdgeMap*);
template PredecodedCore::Batch PredecodedCore::run_batch<true>(avr_t*, const BatchLimits&, PcEdgeMap*);

}  // namespace avrbench
