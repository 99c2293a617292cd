/*
 * workloads - the CPU kernels of bench/perf's workload suite (avrbench_perf
 * --workloads), one per build (WORKLOAD = 1..9), each a fixed amount of work
 * that ends at the label `workload_done` (then power-down with interrupts
 * off, where simavr stops), so the bench, bare simavr and qemu-system-avr run
 * the same instructions to the same place. Each stresses a different part
 * of an AVR core:
 *
 *   1 int_div     8/16/32-bit add, shift and division (the libgcc __udivmod*
 *                 loops: compare/subtract/rotate chains)
 *   2 fixed_mul   Q15 FIR filter: MUL/MULS/FMUL-heavy 16x16->32 products
 *   3 soft_float  float add/mul/div and conversions (libgcc/avr-libc soft float)
 *   4 memory      block copies and pointer walks: LD/ST with pre/post
 *                 increment and displacement (LDD/STD), a linked list
 *   5 flash_table table-driven CRC-16 from flash (LPM Z+)
 *   6 branches    a bytecode interpreter: a switch table (IJMP) and
 *                 conditional branches
 *   7 calls       recursion and stack traffic: CALL/RET, PUSH/POP frames
 *   8 interrupts  Timer1 compare match A in CTC mode at clk/1, OCR1A 255
 *                 (every 256 cycles) while main counts: interrupt entry and
 *                 exit, RETI, SREG saves (Timer1: qemu-system-avr 7.2 models
 *                 the 16-bit timers only)
 *   9 mixed       CRC-32 (bitwise), an insertion sort and 32-bit division
 *                 on the same data: the "general code" mix of issue 67
 *
 * Results go to volatile globals (`result`), so nothing is optimised away,
 * and a test can check them against a hand calculation.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/pgmspace.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <string.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#ifndef WORKLOAD
#define WORKLOAD 1
#endif

volatile uint32_t result;
volatile uint8_t seed = 1;  /* volatile: the compiler cannot fold the work */

#if WORKLOAD == 1
static uint32_t kernel(void) {
    uint32_t acc = 0;
    for (uint16_t i = 1; i <= 6000; ++i) {
        const uint32_t big = (uint32_t)i * 48271u + seed;
        acc += big / (uint16_t)(i | 1u);                  /* 32/16 */
        acc ^= (uint16_t)(big >> 3) / (uint8_t)(i | 3u);  /* 16/8 */
        acc += (big % 1000003ul) >> 2;                    /* 32 % 32 */
    }
    return acc;
}
#elif WORKLOAD == 2
static int16_t samples[64];
static const int16_t taps[16] = {-120, 340, -910, 2100, -4500, 9800, 18000, 24000,
                                 24000, 18000, 9800, -4500, 2100, -910, 340, -120};
static uint32_t kernel(void) {
    for (uint8_t i = 0; i < 64; ++i) samples[i] = (int16_t)(((uint16_t)i * 977u + seed) & 0x7FFFu) - 16384;
    uint32_t acc = 0;
    for (uint16_t round = 0; round < 600; ++round) {
        for (uint8_t n = 0; n + 16 <= 64; ++n) {
            int32_t y = 0;
            for (uint8_t k = 0; k < 16; ++k) y += (int32_t)samples[n + k] * taps[k];
            samples[n] = (int16_t)(y >> 15);
            acc += (uint16_t)samples[n];
        }
    }
    return acc;
}
#elif WORKLOAD == 3
static uint32_t kernel(void) {
    float x = (float)seed, sum = 0.0f;
    for (uint16_t i = 1; i <= 3000; ++i) {
        x = x * 1.0001f + 0.5f / (float)i;
        sum += x / (1.0f + (float)(i & 15));
    }
    return (uint32_t)sum;
}
#elif WORKLOAD == 4
struct node {
    struct node* next;
    uint16_t value;
    uint8_t pad[4];
};
static uint8_t a[256], b[256];
static struct node nodes[64];
static uint32_t kernel(void) {
    for (uint16_t i = 0; i < 256; ++i) a[i] = (uint8_t)(i * 7 + seed);
    for (uint8_t i = 0; i < 64; ++i) {
        nodes[i].next = &nodes[(i * 29 + 1) & 63];
        nodes[i].value = i;
    }
    uint32_t acc = 0;
    for (uint16_t round = 0; round < 400; ++round) {
        memcpy(b, a, sizeof b);                 /* post-increment loads and stores */
        const uint8_t* p = b + 255;
        uint8_t* q = a;
        for (uint16_t i = 0; i < 256; ++i) *q++ ^= *p--;  /* pre-decrement */
        const struct node* n = &nodes[round & 63];
        for (uint8_t i = 0; i < 64; ++i) {
            acc += n->value + n->pad[2];        /* LDD with displacement */
            n = n->next;
        }
    }
    return acc;
}
#elif WORKLOAD == 5
/* CRC-16/CCITT-FALSE table (poly 0x1021), built at compile time in flash. */
#define CRC_T(c) ((uint16_t)(c))
static const uint16_t crc_table[256] PROGMEM = {
#define R1(i) (((i) & 0x8000) ? (((i) << 1) ^ 0x1021) : ((i) << 1))
#define R8(i) R1(R1(R1(R1(R1(R1(R1(R1(((uint32_t)(i)) << 8))))))))
#define E(i) (uint16_t)(R8(i) & 0xFFFF)
#define E4(i) E(i), E(i + 1), E(i + 2), E(i + 3)
#define E16(i) E4(i), E4(i + 4), E4(i + 8), E4(i + 12)
#define E64(i) E16(i), E16(i + 16), E16(i + 32), E16(i + 48)
    E64(0), E64(64), E64(128), E64(192)};
static uint8_t data[256];
static uint32_t kernel(void) {
    for (uint16_t i = 0; i < 256; ++i) data[i] = (uint8_t)(i ^ seed);
    uint16_t crc = 0xFFFF;
    for (uint16_t round = 0; round < 300; ++round) {
        for (uint16_t i = 0; i < 256; ++i) {
            crc = (uint16_t)(crc << 8) ^ pgm_read_word(&crc_table[(uint8_t)(crc >> 8) ^ data[i]]);
        }
    }
    return crc;
}
#elif WORKLOAD == 6
enum { OP_ADD, OP_SUB, OP_XOR, OP_SHL, OP_JNZ, OP_DEC, OP_SWAP, OP_HALT };
static const uint8_t program[] = {OP_ADD, OP_XOR, OP_SHL, OP_SUB, OP_SWAP, OP_DEC, OP_JNZ, OP_HALT};
static uint32_t kernel(void) {
    uint32_t acc = 0;
    for (uint16_t round = 0; round < 2000; ++round) {
        uint16_t r0 = round ^ seed, r1 = 40;
        uint8_t pc = 0;
        for (;;) {
            const uint8_t op = program[pc++];
            switch (op) {
                case OP_ADD: r0 += r1; break;
                case OP_SUB: r0 -= 3; break;
                case OP_XOR: r0 ^= 0x5A5A; break;
                case OP_SHL: r0 = (uint16_t)(r0 << 1) | (r0 >> 15); break;
                case OP_SWAP: r0 = (uint16_t)((r0 >> 8) | (r0 << 8)); break;
                case OP_DEC: --r1; break;
                case OP_JNZ: if (r1 != 0) pc = 0; break;
                default: goto halted;
            }
        }
    halted:
        acc += r0;
    }
    return acc;
}
#elif WORKLOAD == 7
static uint16_t __attribute__((noinline)) fib(uint8_t n) { return n < 2 ? n : fib(n - 1) + fib(n - 2); }
static uint32_t __attribute__((noinline)) ackermann(uint8_t m, uint16_t n) {
    if (m == 0) return n + 1u;
    if (n == 0) return ackermann(m - 1, 1);
    return ackermann(m - 1, (uint16_t)ackermann(m, n - 1));
}
static uint32_t kernel(void) {
    uint32_t acc = 0;
    for (uint8_t i = 0; i < 6; ++i) acc += fib((uint8_t)(17 + (seed & 1)));
    acc += ackermann(2, 200);
    return acc;
}
#elif WORKLOAD == 8
static volatile uint16_t overflows;
ISR(TIMER1_COMPA_vect) { ++overflows; }
static uint32_t kernel(void) {
    OCR1A = 255;                           /* a match every 256 cycles */
    TCCR1B = (1 << WGM12) | (1 << CS10);   /* CTC on OCR1A, clk/1 */
    TIMSK1 = (1 << OCIE1A);
    sei();
    uint32_t acc = 0;
    overflows = 0;
    while (overflows < 20000) acc += seed;
    cli();
    TIMSK1 = 0;
    TCCR1B = 0;
    return acc + overflows;
}
#elif WORKLOAD == 9
static uint32_t data[96];
static uint32_t kernel(void) {
    uint32_t x = 0x12345678u ^ seed, acc = 0;
    for (uint8_t round = 0; round < 12; ++round) {
        for (uint8_t i = 0; i < 96; ++i) {
            x ^= x << 13, x ^= x >> 17, x ^= x << 5;  /* xorshift32 */
            data[i] = x;
        }
        /* CRC-32 (poly 0xEDB88320), bitwise */
        uint32_t crc = 0xFFFFFFFFu;
        const uint8_t* p = (const uint8_t*)data;
        for (uint16_t i = 0; i < sizeof data; ++i) {
            crc ^= p[i];
            for (uint8_t k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (uint32_t)-(int32_t)(crc & 1));
        }
        /* insertion sort */
        for (uint8_t i = 1; i < 96; ++i) {
            const uint32_t v = data[i];
            uint8_t j = i;
            while (j > 0 && data[j - 1] > v) {
                data[j] = data[j - 1];
                --j;
            }
            data[j] = v;
        }
        /* 32-bit division */
        for (uint8_t i = 1; i < 96; ++i) acc += data[i] / (data[i - 1] / 65536u + 1u);
        acc ^= ~crc;
    }
    return acc;
}
#endif

/* Repetitions of each kernel: about 100-150 M cycles in all (7-9 s of
 * simulated time), enough for qemu-system-avr's CPU time, polled every
 * 5 ms, to be measured to about 1 %. */
#if WORKLOAD == 1
#define REPEATS 14
#elif WORKLOAD == 2
#define REPEATS 4
#elif WORKLOAD == 3
#define REPEATS 25
#elif WORKLOAD == 4
#define REPEATS 50
#elif WORKLOAD == 5
#define REPEATS 68
#elif WORKLOAD == 6
#define REPEATS 6
#elif WORKLOAD == 7
#define REPEATS 41
#elif WORKLOAD == 8
#define REPEATS 24
#else
#define REPEATS 35
#endif

int main(void) {
    uint32_t sum = 0;
    for (uint8_t r = 0; r < REPEATS; ++r) sum += kernel();
    result = sum;
    /* The jump ends qemu's translation block here, so its monitor shows
     * the PC at workload_done once the work is done (QEMU reports a TB's
     * first PC: one running on into the end loop would still show the
     * last address before it). */
    __asm__ __volatile__("rjmp workload_done\n"
                         ".global workload_done\n"
                         "workload_done:\n\t");
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    sleep_enable();
    cli();
    for (;;) sleep_cpu();
}
