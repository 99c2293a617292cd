#include "mcu/BlockTranslator.hpp"

#include <algorithm>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__) && defined(__linux__)
#include <sys/mman.h>
#define AVRBENCH_TRANSLATE_BLOCKS 1
#else
#define AVRBENCH_TRANSLATE_BLOCKS 0
#endif

extern "C" {
#include <sim_core.h>
}

#include "core/ProcessHeap.hpp"

namespace avrbench {

namespace {

using Op = BlockTranslator::Op;

// SREG's flags as bits, for the liveness pass (the bit numbers are simavr's
// avr->sreg[] indexes: C Z N V S H T I).
constexpr unsigned kC = 1u << S_C, kZ = 1u << S_Z, kN = 1u << S_N, kV = 1u << S_V, kS = 1u << S_S, kH = 1u << S_H, kT = 1u << S_T;
constexpr unsigned kArithFlags = kC | kZ | kN | kV | kS | kH;
constexpr unsigned kAllFlags = 0xffu;

unsigned flags_written(const BlockTranslator::Instruction& in) {
    switch (in.op) {
        case Op::kAdd: case Op::kAdc: case Op::kSub: case Op::kSbc: case Op::kCp: case Op::kCpc:
        case Op::kCpi: case Op::kSubi: case Op::kSbci: case Op::kNeg:
            return kArithFlags;
        case Op::kAnd: case Op::kOr: case Op::kEor: case Op::kAndi: case Op::kOri: case Op::kInc: case Op::kDec:
            return kZ | kN | kV | kS;
        case Op::kCom: case Op::kLsr: case Op::kAsr: case Op::kRor: case Op::kAdiw: case Op::kSbiw:
            return kC | kZ | kN | kV | kS;
        case Op::kMul: return kC | kZ;
        case Op::kBst: return kT;
        case Op::kSregSet: case Op::kSregClear: return 1u << in.a;
        default: return 0;
    }
}

unsigned flags_read(const BlockTranslator::Instruction& in) {
    switch (in.op) {
        case Op::kAdc: case Op::kRor: return kC;
        case Op::kSbc: case Op::kCpc: case Op::kSbci: return kC | kZ;  // the carry in, and Z kept only if set
        case Op::kBld: return kT;
        case Op::kBrbs: case Op::kBrbc: return 1u << in.b;
        // The interpreter may take over in front of these (a side exit):
        // every flag must be in SREG there.
        case Op::kLdX: case Op::kLdY: case Op::kLdZ: case Op::kStX: case Op::kStY: case Op::kStZ:
        case Op::kLddY: case Op::kLddZ: case Op::kStdY: case Op::kStdZ: case Op::kLpm: case Op::kLpmInc:
        case Op::kPush: case Op::kPop: case Op::kRcall: case Op::kCall: case Op::kRet: case Op::kIjmp: case Op::kIcall:
            return kAllFlags;
        default: return 0;
    }
}

#if AVRBENCH_TRANSLATE_BLOCKS

// SREG's bytes from the host's flags after an instruction, through LAHF
// (AH = SF:ZF:0:AF:0:PF:1:CF, Intel SDM vol. 2) and SETO or SETC. The
// index is AH * 2 + a bit (OF, or the carry out of a shift): one LEA, which
// leaves the host's flags alone (see Emitter). CF is AVR's carry (borrow)
// C, AF the carry (borrow) out of bit 3, H, ZF Z, SF N, OF V, S = N ^ V
// (AVR Instruction Set Manual, each instruction's flag equations; the
// interpreter's add8/sub8 use the same identities).
struct Tables {
    std::uint32_t arith_c_to_v[512];   // bytes C Z N V at sreg + 0 (ADD ... SBCI, NEG, ADIW, SBIW)
    std::uint16_t arith_s_h[512];      // bytes S H at sreg + 4
    std::uint32_t logic_z_to_s[512];   // bytes Z N V S at sreg + 1 (AND, OR, EOR, INC, DEC, COM: C and H untouched)
    // LSR, ASR, ROR (index AH * 2 + the bit shifted out): C the bit, Z and
    // N the result's (ZF, SF), V = N ^ C, S = N ^ V (the interpreter's
    // flags_zcvs and flags_zcnvs).
    std::uint32_t shift_c_to_v[512];
    std::uint8_t shift_s[512];
    constexpr Tables() : arith_c_to_v{}, arith_s_h{}, logic_z_to_s{}, shift_c_to_v{}, shift_s{} {
        for (unsigned index = 0; index < 512; ++index) {
            const unsigned ah = index >> 1, bit = index & 1u;
            const unsigned cf = ah & 1u, af = (ah >> 4) & 1u, zf = (ah >> 6) & 1u, sf = (ah >> 7) & 1u;
            const unsigned of = bit;
            arith_c_to_v[index] = cf | zf << 8 | sf << 16 | of << 24;
            arith_s_h[index] = static_cast<std::uint16_t>((sf ^ of) | af << 8);
            logic_z_to_s[index] = zf | sf << 8 | of << 16 | (sf ^ of) << 24;
            const unsigned c = bit, v = sf ^ c;
            shift_c_to_v[index] = c | zf << 8 | sf << 16 | v << 24;
            shift_s[index] = static_cast<std::uint8_t>(sf ^ v);
        }
    }
};
constexpr Tables kTables{};
static_assert(S_C == 0 && S_Z == 1 && S_N == 2 && S_V == 3 && S_S == 4 && S_H == 5 && S_T == 6);

// x86-64 machine code, appended byte by byte. Registers in the code:
// rdi = data (the register file at data[0..31]), rsi = sreg (one byte per
// flag), r8 = &kTables, r11d = 0; r9b holds AVR's Z and the host's CF is
// AVR's C wherever the translation says so (below); scratch eax, ecx,
// edx, r10d. All are caller-saved (System V), so the code needs no frame.
//
// Why the flags are kept in host registers: an ADC or CPC chain (32-bit
// arithmetic) through SREG in memory waits at each link for a store to
// reach the next load, then for a table load - 10-15 cycles, where the
// host's own ADC/SBB chain takes one. So the code between two instructions
// of a chain (the flag stores for SREG, kept for what reads it later)
// leaves the host's flags alone: LAHF, SETcc, MOVZX, LEA, MOV and CMOV
// change none. And every load here is a byte load: a wider one over bytes
// that separate stores just wrote cannot take them from the store buffer
// and waits for them to reach the cache (Intel's optimization manual,
// "store forwarding"; a first version with a 32-bit load of C and 16-bit
// loads for MOVW ran 50 % slower than the interpreter).
class Emitter {
public:
    std::vector<std::uint8_t> bytes;
    bool cf_is_c = false;  // the host's CF holds AVR's C
    bool r9_is_z = false;  // r9b holds AVR's Z (0 or 1)

    void put(std::initializer_list<std::uint8_t> b) { bytes.insert(bytes.end(), b); }
    void put32(std::uint32_t v) {
        for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    void put64(std::uint64_t v) {
        for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    // ModRM for reg, [rdi + disp8] (the register file).
    static std::uint8_t at_data(int reg) { return static_cast<std::uint8_t>(0x40 | (reg << 3) | 7); }
    static constexpr int kEax = 0, kEcx = 1, kEdx = 2, kCh = 5;
    static std::uint8_t u8(unsigned v) { return static_cast<std::uint8_t>(v); }

    void prologue() {
        put({0x49, 0xb8});                       // movabs $kTables, %r8
        put64(reinterpret_cast<std::uint64_t>(&kTables));
        put({0x45, 0x31, 0xc9});                 // xor %r9d, %r9d
        put({0x45, 0x31, 0xd2});                 // xor %r10d, %r10d
        put({0x45, 0x31, 0xdb});                 // xor %r11d, %r11d
        cf_is_c = r9_is_z = false;
    }
    void load_cl(unsigned r) { put({0x0f, 0xb6, at_data(kEcx), u8(r)}); }   // movzbl r(%rdi), %ecx
    void load_eax(unsigned r) { put({0x0f, 0xb6, at_data(kEax), u8(r)}); }  // movzbl r(%rdi), %eax
    void load_edx(unsigned r) { put({0x0f, 0xb6, at_data(kEdx), u8(r)}); }  // movzbl r(%rdi), %edx
    void store_cl(unsigned r) { put({0x88, at_data(kEcx), u8(r)}); }        // mov %cl, r(%rdi)
    void store_al(unsigned r) { put({0x88, at_data(kEax), u8(r)}); }        // mov %al, r(%rdi)
    void store_dl(unsigned r) { put({0x88, at_data(kEdx), u8(r)}); }        // mov %dl, r(%rdi)
    // op r(%rdi), %cl: ADD 02, ADC 12, SUB 2A, SBB 1A, AND 22, OR 0A, XOR 32.
    void alu_cl_mem(std::uint8_t opcode, unsigned r) { put({opcode, at_data(kEcx), u8(r)}); }
    // op $k, %cl: 80 /digit ib (ADD 0, OR 1, ADC 2, SBB 3, AND 4, SUB 5, XOR 6).
    void alu_cl_imm(int digit, unsigned k) { put({0x80, u8(0xc1 | (digit << 3)), u8(k)}); }
    // CF = AVR's C, from SREG unless it is already there.
    void carry_in() {
        if (cf_is_c) return;
        put({0x0f, 0xb6, 0x06});  // movzbl C(%rsi), %eax
        put({0x04, 0xff});        // add $0xff, %al: CF = C != 0
    }
    // r9b = AVR's Z, from SREG unless it is already there.
    void z_in() {
        if (r9_is_z) return;
        put({0x44, 0x0f, 0xb6, 0x4e, S_Z});  // movzbl Z(%rsi), %r9d
        r9_is_z = true;
    }
    // After a flag-setting instruction: AH and OF (or with `shift_bit`, the
    // bit r10b holds) as the index in rax; r9b = ZF, or with `keep_z`
    // r9b &= ZF (CMOVNZ of r11d's zero). Host flags untouched.
    void flags_index(bool keep_z, bool shift_bit) {
        put({0x9f});                                 // lahf
        if (!shift_bit) put({0x0f, 0x90, 0xc2});     // seto %dl
        if (keep_z)
            put({0x45, 0x0f, 0x45, 0xcb});           // cmovnz %r11d, %r9d
        else
            put({0x41, 0x0f, 0x94, 0xc1});           // setz %r9b
        r9_is_z = true;
        put({0x0f, 0xb6, 0xc4});                     // movzbl %ah, %eax
        if (shift_bit) {
            put({0x49, 0x8d, 0x04, 0x42});           // lea (%r10,%rax,2), %rax
        } else {
            put({0x0f, 0xb6, 0xd2});                 // movzbl %dl, %edx
            put({0x48, 0x8d, 0x04, 0x42});           // lea (%rdx,%rax,2), %rax
        }
    }
    void table_edx32(std::size_t offset) { put({0x41, 0x8b, 0x94, 0x80}); put32(u32(offset)); }        // mov off(%r8,%rax,4), %edx
    void table_edx16(std::size_t offset) { put({0x41, 0x0f, 0xb7, 0x94, 0x40}); put32(u32(offset)); }  // movzwl off(%r8,%rax,2), %edx
    void table_edx8(std::size_t offset) { put({0x41, 0x0f, 0xb6, 0x94, 0x00}); put32(u32(offset)); }   // movzbl off(%r8,%rax,1), %edx
    static std::uint32_t u32(std::size_t v) { return static_cast<std::uint32_t>(v); }
    void sreg_store_edx32(unsigned at) { put({0x89, 0x56, u8(at)}); }   // mov %edx, at(%rsi)
    void sreg_store_dx(unsigned at) { put({0x66, 0x89, 0x56, u8(at)}); }  // mov %dx, at(%rsi)
    void sreg_store_dl(unsigned at) { put({0x88, 0x56, u8(at)}); }      // mov %dl, at(%rsi)
    void sreg_store_z_from_r9() { put({0x44, 0x88, 0x4e, S_Z}); }        // mov %r9b, Z(%rsi)
    void sreg_byte(unsigned bit, unsigned value) { put({0xc6, 0x46, u8(bit), u8(value)}); }  // movb $v, bit(%rsi)
    // C Z N V S, and H unless `no_h` (ADIW, SBIW), from the arithmetic tables.
    void arith_flags(bool keep_z, bool no_h) {
        flags_index(keep_z, false);
        table_edx32(offsetof(Tables, arith_c_to_v));
        sreg_store_edx32(S_C);
        table_edx16(offsetof(Tables, arith_s_h));
        if (no_h)
            sreg_store_dl(S_S);
        else
            sreg_store_dx(S_S);
        if (keep_z) sreg_store_z_from_r9();
    }
    // mov $pc, %eax; mov $charge, %edx (the Exit in rax:rdx), no flags touched.
    void exit_values(std::uint32_t pc, std::int64_t charge) {
        put({0xb8});
        put32(pc);
        put({0xba});
        put32(static_cast<std::uint32_t>(charge));
    }
    void ret(std::uint32_t pc, std::int64_t charge) {
        exit_values(pc, charge);
        put({0xc3});
    }
    // The same with the new PC already in eax (RET, IJMP, ICALL).
    void ret_pc_in_eax(std::int64_t charge) {
        put({0xba});  // mov $charge, %edx
        put32(static_cast<std::uint32_t>(charge));
        put({0xc3});
    }

    // Side exits: in front of the instruction being emitted (pc_now), with
    // the charge of those before it; the stubs go after the block's body.
    struct Stub {
        std::size_t rel32_at;
        std::uint32_t pc;
        std::int64_t charge;
    };
    std::vector<Stub> stubs;
    std::uint32_t pc_now = 0;
    std::int64_t charge_now = 0;
    void exit_if(std::uint8_t jcc) {  // 0F 8x rel32
        put({0x0f, jcc});
        stubs.push_back({bytes.size(), pc_now, charge_now});
        put32(0);
    }
    void emit_stubs() {
        for (const Stub& stub : stubs) {
            const auto rel = static_cast<std::uint32_t>(bytes.size() - (stub.rel32_at + 4));
            for (int i = 0; i < 4; ++i) bytes[stub.rel32_at + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(rel >> (8 * i));
            ret(stub.pc, stub.charge);
        }
    }
    // edx = the 16-bit value of the register pair at `low` (clobbers eax, flags).
    void pair_edx(unsigned low) {
        load_edx(low + 1);
        put({0xc1, 0xe2, 0x08});  // shl $8, %edx
        load_eax(low);
        put({0x09, 0xc2});        // or %eax, %edx
        cf_is_c = false;
    }
    void add_edx(int k) { put({0x8d, 0x52, static_cast<std::uint8_t>(static_cast<std::int8_t>(k))}); }  // lea k(%rdx), %edx
    // Leaves unless first <= edx <= last (clobbers eax, flags).
    void exit_unless_within(std::uint32_t first, std::uint32_t last) {
        if (first > last) {
            put({0xe9});  // jmp: never within
            stubs.push_back({bytes.size(), pc_now, charge_now});
            put32(0);
            return;
        }
        put({0x8d, 0x82});        // lea -first(%rdx), %eax
        put32(static_cast<std::uint32_t>(-static_cast<std::int64_t>(first)));
        put({0x3d});              // cmp $(last - first), %eax
        put32(last - first);
        exit_if(0x87);            // ja
        cf_is_c = false;
    }
    void store_dx_pair(unsigned low) {
        store_dl(low);
        put({0x88, at_data(6), u8(low + 1)});  // mov %dh, low+1(%rdi)
    }
    // The return address (words) pushed downwards from SP = edx, low byte
    // first (_avr_push_addr), then SP below it; leaves unless all of it is
    // plain RAM and SP stays at or above the floor. Clobbers eax, ecx.
    void push_return(std::uint32_t return_pc, const BlockTranslator::Memory& memory) {
        const auto size = static_cast<std::uint32_t>(memory.address_size);
        pair_edx(R_SPL);
        exit_unless_within(std::max<std::uint32_t>(memory.ram_begin + size - 1, memory.stack_floor + size), memory.ramend);
        std::uint32_t word = return_pc >> 1;
        for (std::uint32_t i = 0; i < size; ++i, word >>= 8) {
            put({0xc6, 0x44, 0x17, u8(0x100 - i), u8(word)});  // movb $byte, -i(%rdi,%rdx,1)
        }
        add_edx(-static_cast<int>(size));
        store_dx_pair(R_SPL);
    }
    // Leaves unless the new PC in eax passes the PC oracles (as the
    // interpreter's check after an instruction: PC - 1 at or past the code's
    // end - 1, or the bad-interrupt handler). Clobbers ecx, flags.
    void exit_unless_pc_passes(const BlockTranslator::Memory& memory) {
        put({0x8d, 0x48, 0xff});            // lea -1(%rax), %ecx
        put({0x81, 0xf9});                  // cmp $code_end_minus_one, %ecx
        put32(memory.code_end_minus_one);
        exit_if(0x83);                      // jae
        put({0x3d});                        // cmp $bad_interrupt_pc, %eax
        put32(memory.bad_interrupt_pc);
        exit_if(0x84);                      // je
    }
    void load_cl_at_edx() { put({0x0f, 0xb6, 0x0c, 0x17}); }  // movzbl (%rdi,%rdx,1), %ecx
    void store_cl_at_edx() { put({0x88, 0x0c, 0x17}); }       // mov %cl, (%rdi,%rdx,1)
};

// How much of an instruction's flags the code computes: none (every flag
// it sets is set again before anything reads it), only the host registers
// (C in CF, Z in r9b: all that is read, by the next instruction, which
// takes them from there and sets them again - the links of an ADC or CPC
// chain), or SREG's bytes as well.
enum class FlagWork { kNone, kRegisters, kAll };

// One instruction.
void emit(Emitter& e, const BlockTranslator::Instruction& in, FlagWork work, avr_flashaddr_t next_pc, std::int64_t charge_after,
          std::int64_t cycle_charge, const BlockTranslator::Memory& memory) {
    const unsigned a = in.a, b = in.b;
    const bool flags = work == FlagWork::kAll;
    const bool light = work == FlagWork::kRegisters;
    // r9b = Z after a flag-setting instruction, without SREG.
    const auto z_to_r9 = [&](bool keep_z) {
        if (keep_z)
            e.put({0x45, 0x0f, 0x45, 0xcb});  // cmovnz %r11d, %r9d
        else
            e.put({0x41, 0x0f, 0x94, 0xc1});  // setz %r9b
        e.r9_is_z = true;
    };
    // ADD/ADC/SUB/SBC and their compare and immediate forms: the host's own.
    const auto arith = [&](std::uint8_t mem_opcode, int imm_digit, bool carry, bool keep_z, bool store, bool immediate) {
        if (!flags && !light && !store) return;  // a compare nothing reads
        e.load_cl(a);
        if (keep_z && (flags || light)) e.z_in();
        if (carry) e.carry_in();
        if (immediate)
            e.alu_cl_imm(imm_digit, b);
        else
            e.alu_cl_mem(mem_opcode, b);
        e.cf_is_c = true;
        e.r9_is_z = false;
        if (flags) e.arith_flags(keep_z, false);
        if (light) z_to_r9(keep_z);
        if (store) e.store_cl(a);
    };
    // AND, OR, EOR and their immediate forms, INC, DEC, COM: Z N V S.
    const auto logic = [&](std::initializer_list<std::uint8_t> host_op, bool keeps_cf) {
        e.load_cl(a);
        e.put(host_op);
        if (!keeps_cf) e.cf_is_c = false;
        e.r9_is_z = false;
        if (flags) {
            e.flags_index(false, false);
            e.table_edx32(offsetof(Tables, logic_z_to_s));
            e.sreg_store_edx32(S_Z);
        }
        e.store_cl(a);
    };
    // LSR, ASR, ROR: the host's SHR, SAR, RCR by one.
    const auto shift = [&](std::uint8_t modrm, bool rotate) {
        e.load_cl(a);
        if (rotate) e.carry_in();
        e.put({0xd0, modrm});                        // shr/sar/rcr %cl
        e.cf_is_c = true;
        e.r9_is_z = false;
        if (light && !rotate) z_to_r9(false);        // (RCR sets no ZF: the translation asks for C only)
        if (flags) e.put({0x41, 0x0f, 0x92, 0xc2});  // setc %r10b: the bit shifted out
        if (flags) {
            if (rotate) e.put({0x84, 0xc9});         // test %cl, %cl: RCR sets no ZF or SF
            e.flags_index(false, true);
            e.table_edx32(offsetof(Tables, shift_c_to_v));
            e.sreg_store_edx32(S_C);
            e.table_edx8(offsetof(Tables, shift_s));
            e.sreg_store_dl(S_S);
            if (rotate) e.put({0x41, 0x0f, 0xba, 0xe2, 0x00});  // bt $0, %r10d: CF = C again
        }
        e.store_cl(a);
    };
    switch (in.op) {
        case Op::kNop: break;
        case Op::kAdd: arith(0x02, 0, false, false, true, false); break;
        case Op::kAdc: arith(0x12, 0, true, false, true, false); break;
        case Op::kSub: arith(0x2a, 0, false, false, true, false); break;
        case Op::kSbc: arith(0x1a, 0, true, true, true, false); break;
        case Op::kCp: arith(0x2a, 0, false, false, false, false); break;
        case Op::kCpc: arith(0x1a, 0, true, true, false, false); break;
        case Op::kCpi: arith(0, 5, false, false, false, true); break;
        case Op::kSubi: arith(0, 5, false, false, true, true); break;
        case Op::kSbci: arith(0, 3, true, true, true, true); break;
        // The host's AND/OR/XOR clear CF (AVR's leave C): OF 0 is AVR's V.
        case Op::kAnd: logic({0x22, Emitter::at_data(Emitter::kEcx), Emitter::u8(b)}, false); break;
        case Op::kOr: logic({0x0a, Emitter::at_data(Emitter::kEcx), Emitter::u8(b)}, false); break;
        case Op::kEor: logic({0x32, Emitter::at_data(Emitter::kEcx), Emitter::u8(b)}, false); break;
        case Op::kAndi: logic({0x80, 0xe1, Emitter::u8(b)}, false); break;
        case Op::kOri: logic({0x80, 0xc9, Emitter::u8(b)}, false); break;
        // The host's INC/DEC: OF set exactly for a result of 0x80 / 0x7F (the
        // interpreter's V), ZF, SF; CF untouched, as AVR's C and H are.
        case Op::kInc: logic({0xfe, 0xc1}, true); break;
        case Op::kDec: logic({0xfe, 0xc9}, true); break;
        case Op::kCom:
            logic({0x80, 0xf1, 0xff}, false);  // XOR $0xFF: 0xFF - Rd, OF 0
            if (flags) {
                e.sreg_byte(S_C, 1);
                e.put({0xf9});                  // stc
                e.cf_is_c = true;
            }
            break;
        case Op::kNeg:
            // The host's NEG: CF = Rd != 0 (the interpreter's res != 0), OF =
            // Rd == 0x80 (res == 0x80), AF = a borrow from bit 4 = Rd's low
            // nibble nonzero, which is the interpreter's H = R3 | Rd3 (a low
            // nibble 1..7 negates to 9..15, bit 3 set; 8..15 has bit 3 set).
            e.load_cl(a);
            e.put({0xf6, 0xd9});  // neg %cl
            e.cf_is_c = true;
            e.r9_is_z = false;
            if (flags) e.arith_flags(false, false);
            if (light) z_to_r9(false);
            e.store_cl(a);
            break;
        case Op::kMov:
            e.load_eax(b);
            e.store_al(a);
            break;
        case Op::kMovw:
            e.load_eax(b);
            e.load_edx(b + 1);
            e.store_al(a);
            e.store_dl(a + 1);
            break;
        case Op::kLdi: e.put({0xc6, Emitter::at_data(0), Emitter::u8(a), Emitter::u8(b)}); break;  // movb $K, a(%rdi)
        case Op::kSwap:
            e.load_eax(a);
            e.put({0xc0, 0xc0, 0x04});  // rol $4, %al
            e.cf_is_c = false;
            e.store_al(a);
            break;
        case Op::kLsr: shift(0xe9, false); break;
        case Op::kAsr: shift(0xf9, false); break;
        case Op::kRor: shift(0xd9, true); break;
        case Op::kMul:
            e.load_eax(a);
            e.load_cl(b);
            e.put({0x0f, 0xaf, 0xc1});              // imul %ecx, %eax
            e.put({0x66, 0x89, 0x47, 0x00});        // mov %ax, 0(%rdi): r1:r0
            e.cf_is_c = false;
            e.r9_is_z = false;
            if (flags) {
                e.put({0x66, 0x85, 0xc0});          // test %ax, %ax
                e.put({0x41, 0x0f, 0x94, 0xc1});    // setz %r9b
                e.r9_is_z = true;
                e.sreg_store_z_from_r9();
                e.put({0xc1, 0xe8, 0x0f});          // shr $15, %eax
                e.put({0x88, 0x46, S_C});           // mov %al, C(%rsi)
            }
            break;
        case Op::kAdiw:
        case Op::kSbiw:
            // The host's 16-bit ADD/SUB of K (0..63): CF the carry (borrow)
            // out of bit 15, OF the signed overflow - the interpreter's C and
            // V for a positive K -, ZF, SF; H untouched.
            e.load_cl(a + 1);
            e.put({0xc1, 0xe1, 0x08});                                // shl $8, %ecx
            e.load_edx(a);
            e.put({0x09, 0xd1});                                      // or %edx, %ecx
            e.put({0x66, 0x83, Emitter::u8(in.op == Op::kAdiw ? 0xc1 : 0xe9), Emitter::u8(b)});  // add/sub $K, %cx
            e.cf_is_c = true;
            e.r9_is_z = false;
            if (flags) e.arith_flags(false, true);
            if (light) z_to_r9(false);
            e.store_cl(a);
            e.put({0x88, Emitter::at_data(Emitter::kCh), Emitter::u8(a + 1)});  // mov %ch, a+1(%rdi)
            break;
        case Op::kBst:
            if (!flags) break;
            e.load_eax(a);
            e.put({0xc1, 0xe8, Emitter::u8(b)});    // shr $b, %eax
            e.put({0x83, 0xe0, 0x01});              // and $1, %eax
            e.put({0x88, 0x46, S_T});               // mov %al, T(%rsi)
            e.cf_is_c = false;
            break;
        case Op::kBld:
            e.load_eax(a);
            e.put({0x83, 0xe0, Emitter::u8(~(1u << b))});  // and $~mask, %eax
            e.put({0x0f, 0xb6, 0x56, S_T});         // movzbl T(%rsi), %edx
            e.put({0xc1, 0xe2, Emitter::u8(b)});    // shl $b, %edx
            e.put({0x09, 0xd0});                    // or %edx, %eax
            e.store_al(a);
            e.cf_is_c = false;
            break;
        case Op::kSregSet:
        case Op::kSregClear: {
            const unsigned value = in.op == Op::kSregSet ? 1 : 0;
            if (a == S_C) e.cf_is_c = false;
            if (a == S_Z) e.r9_is_z = false;
            if (!flags) break;
            e.sreg_byte(a, value);
            if (a == S_C) {
                e.put({static_cast<std::uint8_t>(value ? 0xf9 : 0xf8)});  // stc / clc
                e.cf_is_c = true;
            }
            if (a == S_Z) {
                e.put({0x41, 0xb9});                // mov $value, %r9d
                e.put32(value);
                e.r9_is_z = true;
            }
        } break;
        case Op::kBrbs:
        case Op::kBrbc: {
            // Not taken: the next PC. Taken: the target, one cycle more.
            const bool taken_if_set = in.op == Op::kBrbs;
            e.exit_values(next_pc, charge_after);
            std::uint8_t skip;                      // the jump past the taken path
            if (b == S_C && e.cf_is_c) {
                skip = taken_if_set ? 0x73 : 0x72;  // jnc / jc
            } else if (b == S_Z && e.r9_is_z) {
                e.put({0x45, 0x84, 0xc9});          // test %r9b, %r9b
                skip = taken_if_set ? 0x74 : 0x75;  // je / jne
            } else {
                e.put({0x80, 0x7e, Emitter::u8(b), 0x00});  // cmpb $0, b(%rsi)
                skip = taken_if_set ? 0x74 : 0x75;
            }
            e.put({skip, 10});                      // past the taken path's values
            e.exit_values(in.target, charge_after + cycle_charge);
            e.put({0xc3});
        } break;
        case Op::kRjmp: e.ret(in.target, charge_after); break;
        case Op::kRcall:
        case Op::kCall:
            e.push_return(next_pc, memory);
            e.ret(in.target, charge_after);
            break;
        case Op::kRet: {
            // _avr_pop_addr: the high byte first, upwards from SP + 1.
            const auto size = static_cast<std::uint32_t>(memory.address_size);
            e.pair_edx(R_SPL);
            e.exit_unless_within(memory.ram_begin > 0 ? memory.ram_begin - 1u : 0u, memory.ramend - size);
            e.put({0x31, 0xc0});                            // xor %eax, %eax
            for (std::uint32_t i = 1; i <= size; ++i) {
                e.put({0xc1, 0xe0, 0x08});                  // shl $8, %eax
                e.put({0x0f, 0xb6, 0x4c, 0x17, Emitter::u8(i)});  // movzbl i(%rdi,%rdx,1), %ecx
                e.put({0x09, 0xc8});                        // or %ecx, %eax
            }
            e.put({0x01, 0xc0});                            // add %eax, %eax: bytes
            e.exit_unless_pc_passes(memory);
            e.add_edx(static_cast<int>(size));
            e.store_dx_pair(R_SPL);
            e.ret_pc_in_eax(charge_after);
        } break;
        case Op::kIjmp:
        case Op::kIcall:
            // The new PC Z * 2, checked before anything changes (a side exit
            // leaves the instruction undone), then ICALL's push.
            e.pair_edx(R_ZL);
            e.put({0x8d, 0x04, 0x12});                      // lea (%rdx,%rdx,1), %eax
            e.exit_unless_pc_passes(memory);
            if (in.op == Op::kIcall) {
                e.put({0x41, 0x89, 0xc2});                  // mov %eax, %r10d
                e.push_return(next_pc, memory);
                e.put({0x44, 0x89, 0xd0});                  // mov %r10d, %eax
            }
            e.ret_pc_in_eax(charge_after);
            break;
        // LD/ST Rd, X/Y/Z (+/-): the pointer written back before Rd, as the
        // interpreter does (simavr's order, for the undefined LD r26, X+).
        case Op::kLdX: case Op::kLdY: case Op::kLdZ:
        case Op::kStX: case Op::kStY: case Op::kStZ: {
            const bool load = in.op == Op::kLdX || in.op == Op::kLdY || in.op == Op::kLdZ;
            const unsigned base = (in.op == Op::kLdX || in.op == Op::kStX) ? R_XL : (in.op == Op::kLdY || in.op == Op::kStY) ? R_YL : R_ZL;
            if (!load) e.load_cl(a);  // Rd before the pointer moves (ST X+, r26)
            e.pair_edx(base);
            if (b == 2) e.add_edx(-1);
            e.exit_unless_within(memory.ram_begin, memory.ramend);
            if (load)
                e.load_cl_at_edx();
            else
                e.store_cl_at_edx();
            if (b == 1) e.add_edx(1);
            if (b != 0) e.store_dx_pair(base);
            if (load) e.store_cl(a);
        } break;
        case Op::kLddY: case Op::kLddZ:
        case Op::kStdY: case Op::kStdZ: {
            const bool load = in.op == Op::kLddY || in.op == Op::kLddZ;
            const unsigned base = (in.op == Op::kLddY || in.op == Op::kStdY) ? R_YL : R_ZL;
            if (!load) e.load_cl(a);
            e.pair_edx(base);
            if (b != 0) e.add_edx(b);
            e.exit_unless_within(memory.ram_begin, memory.ramend);
            if (load) {
                e.load_cl_at_edx();
                e.store_cl(a);
            } else {
                e.store_cl_at_edx();
            }
        } break;
        // LDS/STS of plain RAM (PredecodedCore translates no other address).
        case Op::kLds:
            e.put({0x0f, 0xb6, 0x87});  // movzbl address(%rdi), %eax
            e.put32(in.target);
            e.store_al(a);
            break;
        case Op::kSts:
            e.load_eax(a);
            e.put({0x88, 0x87});        // mov %al, address(%rdi)
            e.put32(in.target);
            break;
        // LPM Rd, Z (+): Z past the flash is avr_run_one's.
        case Op::kLpm:
        case Op::kLpmInc:
            e.pair_edx(R_ZL);
            e.put({0x81, 0xfa});        // cmp $flashend, %edx
            e.put32(memory.flashend);
            e.exit_if(0x87);            // ja
            e.put({0x48, 0xb8});        // movabs $flash, %rax
            e.put64(reinterpret_cast<std::uint64_t>(memory.flash));
            e.put({0x0f, 0xb6, 0x04, 0x10});  // movzbl (%rax,%rdx,1), %eax
            e.store_al(a);
            if (in.op == Op::kLpmInc) {
                e.add_edx(1);
                e.store_dx_pair(R_ZL);  // Z + 1, modulo 65 536
            }
            break;
        // PUSH/POP on a plain stack, where SP stays at or above the floor
        // (the oracle's finding is the interpreter's to make).
        case Op::kPush:
            e.load_cl(a);
            e.pair_edx(R_SPL);
            e.exit_unless_within(std::max<std::uint32_t>(memory.ram_begin, memory.stack_floor + 1u), memory.ramend);
            e.store_cl_at_edx();
            e.add_edx(-1);
            e.store_dx_pair(R_SPL);
            break;
        case Op::kPop:
            e.pair_edx(R_SPL);
            e.add_edx(1);
            e.exit_unless_within(std::max<std::uint32_t>(memory.ram_begin, memory.stack_floor), memory.ramend);
            e.load_cl_at_edx();
            e.store_dx_pair(R_SPL);
            e.store_cl(a);
            break;
    }
}

#endif

}  // namespace

bool BlockTranslator::available() { return AVRBENCH_TRANSLATE_BLOCKS != 0; }

int BlockTranslator::cycles_of(Op op, int address_size) {
    switch (op) {
        // PredecodedOps.inc: RCALL 1 + size, CALL 2 + size, RET 2 + size, ICALL 1 + size, IJMP 2.
        case Op::kRcall: case Op::kIcall: return 1 + address_size;
        case Op::kCall: case Op::kRet: return 2 + address_size;
        case Op::kIjmp: return 2;
        case Op::kMul: case Op::kAdiw: case Op::kSbiw: case Op::kRjmp:
        case Op::kLdX: case Op::kLdY: case Op::kLdZ: case Op::kStX: case Op::kStY: case Op::kStZ:
        case Op::kLddY: case Op::kLddZ: case Op::kStdY: case Op::kStdZ: case Op::kLds: case Op::kSts:
        case Op::kPush: case Op::kPop:
            return 2;
        case Op::kLpm: case Op::kLpmInc: return 3;
        default: return 1;
    }
}

BlockTranslator::BlockTranslator() {
#if AVRBENCH_TRANSLATE_BLOCKS
    // Reserved, not committed: the kernel maps a page when code is first
    // written there. 16 MiB holds over 100 000 blocks of typical size.
    constexpr std::size_t kCodeBytes = std::size_t{16} << 20;
    void* p = ::mmap(nullptr, kCodeBytes, PROT_READ | PROT_WRITE | PROT_EXEC, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p != MAP_FAILED) {
        code_ = static_cast<std::uint8_t*>(p);
        code_bytes_ = kCodeBytes;
    }
#endif
}

BlockTranslator::~BlockTranslator() {
#if AVRBENCH_TRANSLATE_BLOCKS
    if (code_ != nullptr) ::munmap(code_, code_bytes_);
#endif
}

int BlockTranslator::translate(const Instruction* instructions, std::size_t count, avr_flashaddr_t head, const Memory& memory,
                               int step_bits) {
#if AVRBENCH_TRANSLATE_BLOCKS
    if (code_ == nullptr || count == 0) return -1;
    // Which flags each instruction must leave: those read later in the
    // block before being set again, and all of them at its end.
    std::vector<unsigned> needed(count);  // the flags each sets that something reads
    unsigned live = kAllFlags;
    for (std::size_t i = count; i-- > 0;) {
        const unsigned written = flags_written(instructions[i]);
        needed[i] = written & live;
        live = (live & ~written) | flags_read(instructions[i]);
    }
    // Where only C and Z are read, by the next instruction alone (it sets
    // them again), and it takes them from the host's CF and r9b (the
    // arithmetic with a carry in, ROR), they stay in the host registers.
    const auto keeps_c_z_in_registers = [](Op op, unsigned flags) {
        switch (op) {
            case Op::kAdd: case Op::kAdc: case Op::kSub: case Op::kSbc: case Op::kCp: case Op::kCpc: case Op::kCpi:
            case Op::kSubi: case Op::kSbci: case Op::kNeg: case Op::kAdiw: case Op::kSbiw: case Op::kLsr: case Op::kAsr:
                return true;
            case Op::kRor: return (flags & kZ) == 0;
            default: return false;
        }
    };
    const auto takes_c_z_from_registers = [](Op op) {
        return op == Op::kAdc || op == Op::kSbc || op == Op::kCpc || op == Op::kSbci || op == Op::kRor;
    };
    std::vector<FlagWork> work(count, FlagWork::kAll);
    for (std::size_t i = 0; i < count; ++i) {
        if (needed[i] == 0) {
            work[i] = FlagWork::kNone;
        } else if (i + 1 < count && (needed[i] & ~(kC | kZ)) == 0 && keeps_c_z_in_registers(instructions[i].op, needed[i]) &&
                   takes_c_z_from_registers(instructions[i + 1].op) && (needed[i] & ~flags_written(instructions[i + 1])) == 0) {
            work[i] = FlagWork::kRegisters;
        }
    }
    const std::int64_t cycle_charge = std::int64_t{1} << step_bits;
    Emitter e;
    e.prologue();
    Block block{};
    block.head = head;
    avr_flashaddr_t pc = head;
    std::int64_t charge = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const Op op = instructions[i].op;
        const avr_flashaddr_t next_pc = pc + 2u * static_cast<unsigned>(words_of(op));
        const std::int64_t charge_after = charge + cycles_of(op, memory.address_size) * cycle_charge + 1;
        e.pc_now = pc;
        e.charge_now = charge;
        emit(e, instructions[i], work[i], next_pc, charge_after, cycle_charge, memory);
        pc = next_pc;
        charge = charge_after;
    }
    block.end = pc;
    const bool branch_at_end = instructions[count - 1].op == Op::kBrbs || instructions[count - 1].op == Op::kBrbc;
    block.max_charge = charge + (branch_at_end ? cycle_charge : 0);
    if (!ends_block(instructions[count - 1].op)) e.ret(pc, charge);
    e.emit_stubs();
    if (code_bytes_ - code_used_ < e.bytes.size()) return -1;
    std::uint8_t* at = code_ + code_used_;
    std::memcpy(at, e.bytes.data(), e.bytes.size());
    code_used_ += (e.bytes.size() + 15) & ~std::size_t{15};
    block.code = reinterpret_cast<Code>(at);
    for (std::size_t i = 0; i < count; ++i) ops_translated_ |= std::uint64_t{1} << static_cast<unsigned>(instructions[i].op);
    const OnProcessHeap outlives_restores;  // beside the slots that point at it (PredecodedCore)
    blocks_.push_back(block);
    return static_cast<int>(blocks_.size() - 1);
#else
    (void)instructions;
    (void)count;
    (void)head;
    (void)memory;
    (void)step_bits;
    return -1;
#endif
}

}  // namespace avrbench
