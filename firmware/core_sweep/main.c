/*
 * core_sweep - every ALU instruction over every operand pair.
 *
 * The workload of tests/core/test_predecoded_core.cpp, which runs it on the
 * predecoded instruction core and on simavr's avr_run_one side by side and
 * compares SREG, registers and RAM after every instruction. Compiled C
 * reaches most instructions, but rarely the signed and fractional
 * multiplies, LPM into R0 or ST through Y+/-Y, and never all operand pairs:
 * the flags (H, V, S above all) differ between operands where a core gets
 * them wrong. So, for a = 0..255 and b = 0..255, each two-operand ALU
 * instruction runs once (the carry-using ones with C clear and with C set),
 * its result and SREG folded into a 16-bit sum; each one-operand instruction
 * and each immediate form runs over every a. The sum ends in `core_sweep_sum`,
 * then the MCU stops (power-down with interrupts off; label core_sweep_done).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t core_sweep_sum;
volatile uint8_t core_sweep_ram[4];
static const uint8_t core_sweep_table[4] PROGMEM = {0x5a, 0xa5, 0x00, 0xff};

/* insn r24(=a), b; fold r24 and SREG into sum. */
#define OP2(pre, insn)                                                            \
    __asm__ __volatile__("mov r24, %[a]\n\t" pre "\n\t" insn " r24, %[b]\n\t"      \
                         "in r25, __SREG__\n\t"                                   \
                         "add %A[s], r24\n\t"                                     \
                         "adc %B[s], r25\n\t"                                     \
                         : [s] "+r"(sum)                                          \
                         : [a] "r"(a), [b] "r"(b)                                 \
                         : "r24", "r25")

/* A multiply of a and b (r16..r23 for all forms); product in r1:r0. */
#define MUL2(insn)                                                                \
    __asm__ __volatile__(insn " %[a], %[b]\n\t"                                   \
                         "in r25, __SREG__\n\t"                                   \
                         "add %A[s], r0\n\t"                                      \
                         "adc %B[s], r1\n\t"                                      \
                         "add %A[s], r25\n\t"                                     \
                         "clr __zero_reg__\n\t"                                   \
                         : [s] "+r"(sum)                                          \
                         : [a] "a"(a), [b] "a"(b)                                 \
                         : "r25")

/* insn r24(=a) with an immediate or none. */
#define OP1(pre, insn)                                                            \
    __asm__ __volatile__("mov r24, %[a]\n\t" pre "\n\t" insn "\n\t"                \
                         "in r25, __SREG__\n\t"                                   \
                         "add %A[s], r24\n\t"                                     \
                         "adc %B[s], r25\n\t"                                     \
                         : [s] "+r"(sum)                                          \
                         : [a] "r"(a)                                             \
                         : "r24", "r25")

/* a word op on r25:r24 = a:b */
#define OPW(insn)                                                                 \
    __asm__ __volatile__("mov r24, %[b]\n\t" "mov r25, %[a]\n\t" insn "\n\t"        \
                         "in r23, __SREG__\n\t"                                   \
                         "add %A[s], r24\n\t"                                     \
                         "adc %B[s], r25\n\t"                                     \
                         "add %A[s], r23\n\t"                                     \
                         : [s] "+r"(sum)                                          \
                         : [a] "r"(a), [b] "r"(b)                                 \
                         : "r23", "r24", "r25")

static uint8_t __attribute__((noinline)) core_sweep_twice(uint8_t v) { return (uint8_t)(v + v); }
/* volatile: the call goes through the pointer (ICALL), not to the function. */
static uint8_t (*volatile core_sweep_fn)(uint8_t) = core_sweep_twice;

int main(void)
{
    uint16_t sum = 0;
    uint8_t a = 0;
    do {
        uint8_t b = 0;
        do {
            OP2("clc", "add");
            OP2("clc", "adc");
            OP2("sec", "adc");
            OP2("clc", "sub");
            OP2("clc", "sbc");
            OP2("sec", "sbc");
            OP2("sez\n\tclc", "sbc");  /* SBC keeps Z only while the result is 0 */
            OP2("clc", "cp");
            OP2("sez\n\tclc", "cpc");
            OP2("sez\n\tsec", "cpc");
            OP2("clz\n\tsec", "cpc");
            OP2("", "and");
            OP2("", "or");
            OP2("", "eor");
            OP2("", "mov");
            /* CPSE skipping a one-word and a two-word instruction. */
            OP2("", "cpse r24, %[b]\n\tinc r24\n\tcpse");
            __asm__ __volatile__("cpse %[a], %[b]\n\t"
                                 "lds r24, core_sweep_ram\n\t"
                                 "add %A[s], r24\n\t"
                                 : [s] "+r"(sum)
                                 : [a] "r"(a), [b] "r"(b)
                                 : "r24");
            MUL2("mul");
            MUL2("muls");
            MUL2("mulsu");
            MUL2("fmul");
            MUL2("fmuls");
            MUL2("fmulsu");
            OPW("adiw r24, 1");
            OPW("adiw r24, 63");
            OPW("sbiw r24, 1");
            OPW("sbiw r24, 63");
        } while (++b != 0);

        OP1("", "com r24");
        OP1("", "neg r24");
        OP1("", "swap r24");
        OP1("", "inc r24");
        OP1("", "dec r24");
        OP1("", "asr r24");
        OP1("", "lsr r24");
        OP1("clc", "ror r24");
        OP1("sec", "ror r24");
        OP1("", "subi r24, 0x80");
        OP1("", "subi r24, 0x01");
        OP1("clc", "sbci r24, 0x7f");
        OP1("sec\n\tsez", "sbci r24, 0x00");
        OP1("", "cpi r24, 0x10");
        OP1("", "cpi r24, 0x80");
        OP1("", "andi r24, 0x0f");
        OP1("", "ori r24, 0x80");
        OP1("clt", "bst r24, 7\n\tbld r24, 0");
        OP1("set", "bld r24, 3\n\tsbrc r24, 0\n\tinc r24\n\tsbrs r24, 1\n\tdec r24");
        OP1("seh\n\tses\n\tsev\n\tsen", "clh\n\tcls\n\tclv");

        /* LPM into R0 and ST/LD through Y+ and -Y. */
        const uint8_t* z = &core_sweep_table[a & 3];
        uint8_t lpm_r0;
        __asm__ __volatile__("lpm\n\tmov %[out], r0" : [out] "=r"(lpm_r0) : "z"(z) : "r0");
        volatile uint8_t* y = core_sweep_ram;
        __asm__ __volatile__("st Y+, %[v]\n\tst Y+, %[w]\n\tst -Y, %[v]\n\tld __tmp_reg__, -Y\n\t"
                             "add %A[s], __tmp_reg__\n\t"
                             : [s] "+r"(sum), "+y"(y)
                             : [v] "r"(a), [w] "r"(lpm_r0));
        /* NOP inside a run of ALU instructions, and ICALL through a
         * function pointer: compiled C rarely emits either. */
        __asm__ __volatile__("mov r24, %[a]\n\tnop\n\tadd %A[s], r24\n\t" : [s] "+r"(sum) : [a] "r"(a) : "r24");
        sum += core_sweep_fn(a);
    } while (++a != 0);

    core_sweep_sum = sum;
    cli();
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    sleep_enable();
    __asm__ __volatile__("core_sweep_done: sleep");
    for (;;) {
    }
}
