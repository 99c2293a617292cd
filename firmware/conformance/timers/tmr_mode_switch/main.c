/*
 * tmr_mode_switch - a timer switched into CTC (or fast PWM with TOP = OCRnA)
 * from any mode, at any point of that mode's period, counts up.
 *
 * Datasheet (ATmega2560 §17.9.1-2, ATmega328P §16.9.1-2 and §15.7.1-2,
 * ATmega32 "Modes of Operation" of each timer): in Normal, CTC and fast PWM
 * modes the counting direction is always up; only the dual-slope (phase
 * correct, phase and frequency correct) modes count down. The Arduino core's
 * init() leaves Timer1 in 8-bit phase correct PWM (mode 1); firmware that
 * then switches to CTC for its stepper interrupt (Marlin 1.x does) depends on
 * this.
 *
 * For each timer, each from-mode (every WGM mode; OCRnA = ICRn = 99 for the
 * modes that take TOP from them) and each of 8 phases of that mode's period:
 * stop, TCNTn = 0, start the from-mode at clk/1, wait phase/8 of its period,
 * toggle marker PC0/PF0, switch to the to-mode with OCnA toggling
 * (COMnA = 01) at clk/1, and wait for 6 compare matches (or give up after
 * about 2^20 cycles), then toggle marker PC1/PF1.
 *
 * Counting up, the to-mode matches every TOP + 1 = 100 timer clocks, so the
 * OCnA edges after the first are 100 cycles apart (up to 65536 + 100 cycles
 * pass before the first when TCNTn was above TOP at the switch). Counting
 * down, matches come 65536 cycles apart, or not at all.
 *
 * To-modes: 16-bit timers CTC with TOP = OCRnA (4), CTC with TOP = ICRn (12,
 * OCRnA = 50 toggles once per period), fast PWM with TOP = OCRnA (15);
 * 8-bit timers CTC (2) and, where it exists, fast PWM with TOP = OCRnA (7).
 * `cases` counts the switches made; `gave_up` those that timed out.
 */
#include <avr/io.h>
#include <util/delay_basic.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t cases;
volatile uint16_t gave_up;
volatile uint8_t done;

#define TOP 99u

/* Period in timer clocks of 16-bit mode `wgm` with OCRnA = ICRn = TOP. */
static uint32_t period16(uint8_t wgm)
{
    static const uint16_t tops[16] = {0xFFFF, 0xFF, 0x1FF, 0x3FF, TOP, 0xFF, 0x1FF, 0x3FF,
                                      TOP,    TOP,  TOP,   TOP,   TOP, TOP,  TOP,   TOP};
    const uint8_t dual = wgm == 1 || wgm == 2 || wgm == 3 || (wgm >= 8 && wgm <= 11);
    return dual ? 2ul * tops[wgm] : (uint32_t)tops[wgm] + 1;
}

/* Waits about `cycles` CPU cycles (4 per _delay_loop_2 iteration). */
static void wait_cycles(uint32_t cycles)
{
    uint16_t n = (uint16_t)(cycles / 4);
    if (n > 0) _delay_loop_2(n);
}

/* Six compare matches, or give up after 2^16 polls (> 2^20 cycles). */
#define AWAIT_MATCHES(tifr, ocf)                           \
    do {                                                   \
        uint8_t matches = 0;                               \
        uint16_t polls = 0;                                \
        tifr = _BV(ocf);                                   \
        while (matches < 6) {                              \
            if (tifr & _BV(ocf)) {                         \
                tifr = _BV(ocf);                           \
                ++matches;                                 \
            }                                              \
            if (++polls == 0) {                            \
                ++gave_up;                                 \
                break;                                     \
            }                                              \
        }                                                  \
    } while (0)

/* One 16-bit timer n: every from-mode x phase, into to-mode `to`. */
#define SWITCH16(A, B, TCNT, OCRA, ICR, TIFR_, OCFA, COMA0, to)                          \
    do {                                                                                  \
        for (uint8_t from = 0; from < 16; ++from) {                                      \
            if (from == 13) continue; /* reserved */                                     \
            for (uint8_t phase = 0; phase < 8; ++phase) {                                \
                B = 0;                                                                    \
                A = 0;                                                                    \
                TCNT = 0;                                                                 \
                OCRA = TOP;                                                               \
                ICR = TOP;                                                                \
                A = (uint8_t)(from & 3);                                                  \
                B = (uint8_t)(((from >> 2) << 3) | 1);                                   \
                wait_cycles(period16(from) * phase / 8);                                 \
                MARK_TOGGLE(0);                                                           \
                A = (uint8_t)(_BV(COMA0) | ((to) & 3));                                  \
                B = (uint8_t)((((to) >> 2) << 3) | 1);                                   \
                /* Written in the new (non-PWM or TOP = OCRnA) mode: */                   \
                if ((to) == 12) OCRA = 50;                                                \
                AWAIT_MATCHES(TIFR_, OCFA);                                               \
                MARK_TOGGLE(1);                                                           \
                ++cases;                                                                  \
            }                                                                             \
        }                                                                                 \
    } while (0)

#if TMR_MODERN
/* One 8-bit timer (TCCRnA: COMnA1:0 WGMn1:0; TCCRnB: WGMn2 CSn2:0). */
#define SWITCH8(A, B, TCNT, OCRA, TIFR_, OCFA, COMA0, to)                                 \
    do {                                                                                  \
        for (uint8_t from = 0; from < 8; ++from) {                                       \
            if (from == 4 || from == 6) continue; /* reserved */                         \
            const uint16_t top = (from == 2 || from == 5 || from == 7) ? TOP : 0xFF;     \
            const uint16_t period = (from == 1 || from == 5) ? 2 * top : top + 1;        \
            for (uint8_t phase = 0; phase < 8; ++phase) {                                \
                B = 0;                                                                    \
                A = 0;                                                                    \
                TCNT = 0;                                                                 \
                OCRA = TOP;                                                               \
                A = (uint8_t)(from & 3);                                                  \
                B = (uint8_t)(((from >> 2) << 3) | 1);                                   \
                wait_cycles((uint32_t)period * phase / 8);                               \
                MARK_TOGGLE(0);                                                           \
                A = (uint8_t)(_BV(COMA0) | ((to) & 3));                                  \
                B = (uint8_t)((((to) >> 2) << 3) | 1);                                   \
                AWAIT_MATCHES(TIFR_, OCFA);                                               \
                MARK_TOGGLE(1);                                                           \
                ++cases;                                                                  \
            }                                                                             \
        }                                                                                 \
    } while (0)
#else
/* ATmega32 8-bit timers: TCCRn = FOCn WGMn0 COMn1 COMn0 WGMn1 CSn2:0; to = CTC. */
#define SWITCH8_M32(TCCR, TCNT, OCR, OCF, COM0)                                           \
    do {                                                                                  \
        for (uint8_t from = 0; from < 4; ++from) {                                       \
            const uint16_t top = from == 2 ? TOP : 0xFF;                                  \
            const uint16_t period = from == 1 ? 2 * top : top + 1;                       \
            for (uint8_t phase = 0; phase < 8; ++phase) {                                \
                TCCR = 0;                                                                 \
                TCNT = 0;                                                                 \
                OCR = TOP;                                                                \
                TCCR = (uint8_t)(((from & 1) ? _BV(6) : 0) | ((from & 2) ? _BV(3) : 0) | 1); \
                wait_cycles((uint32_t)period * phase / 8);                               \
                MARK_TOGGLE(0);                                                           \
                TCCR = (uint8_t)(_BV(3) | _BV(COM0) | 1);                                \
                AWAIT_MATCHES(TIFR, OCF);                                                 \
                MARK_TOGGLE(1);                                                           \
                ++cases;                                                                  \
            }                                                                             \
        }                                                                                 \
    } while (0)
#endif

#if TMR_MODERN
#define TIFR1_ TIFR1
#else
#define TIFR1_ TIFR
#endif

int main(void)
{
    tmr_oc_outputs();
    static const uint8_t to16[3] = {4, 12, 15};
    for (uint8_t t = 0; t < 3; ++t) {
        SWITCH16(TCCR1A, TCCR1B, TCNT1, OCR1A, ICR1, TIFR1_, OCF1A, COM1A0, to16[t]);
#if TMR_SIX
        SWITCH16(TCCR3A, TCCR3B, TCNT3, OCR3A, ICR3, TIFR3, OCF3A, COM3A0, to16[t]);
        SWITCH16(TCCR4A, TCCR4B, TCNT4, OCR4A, ICR4, TIFR4, OCF4A, COM4A0, to16[t]);
        SWITCH16(TCCR5A, TCCR5B, TCNT5, OCR5A, ICR5, TIFR5, OCF5A, COM5A0, to16[t]);
#endif
    }
#if TMR_MODERN
    static const uint8_t to8[2] = {2, 7};
    for (uint8_t t = 0; t < 2; ++t) {
        SWITCH8(TCCR0A, TCCR0B, TCNT0, OCR0A, TIFR0, OCF0A, COM0A0, to8[t]);
        SWITCH8(TCCR2A, TCCR2B, TCNT2, OCR2A, TIFR2, OCF2A, COM2A0, to8[t]);
    }
#else
    SWITCH8_M32(TCCR0, TCNT0, OCR0, OCF0, COM00);
    SWITCH8_M32(TCCR2, TCNT2, OCR2, OCF2, COM20);
#endif
    done = 1;
    for (;;) {
    }
}
