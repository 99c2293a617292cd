/*
 * tmr_flag_timing - which TCNTn value comes with each flag, in every mode.
 *
 * At clk/1024 a timer clock lasts 1024 CPU cycles; the firmware polls TIFRn
 * until the flag shows and reads TCNTn a few cycles later, i.e. in the same
 * timer clock cycle in which the flag was set. Datasheet (ATmega328P
 * §15.8 and §16.10 "Timer/Counter Timing Diagrams", §16.11.9 TIFR1):
 *   OCFnx "is set in the timer clock cycle after the counter (TCNTn) value
 *         matches the Output Compare Register": TCNTn = OCRnx + 1 (up-counting)
 *   TOVn in Normal mode: "set in the same timer clock cycle as the TCNTn
 *         becomes zero": TCNTn = 0
 *   OCFnA in CTC mode: set as TCNTn goes TOP -> BOTTOM: TCNTn = 0
 *   TOVn (and ICFn / OCFnA when it is TOP) in fast PWM: set at TOP, as TCNTn
 *         goes TOP -> BOTTOM: TCNTn = 0
 *   ICFn / OCFnA (TOP) in phase correct PWM: "at the same timer clock cycle as
 *         the OCR1x Registers are updated (at TOP)", TCNTn TOP -> TOP-1
 *         (§16.10): TCNTn = TOP - 1
 *   TOVn in phase correct PWM, "set each time the counter reaches BOTTOM": by
 *         the same figure, on the clock that leaves BOTTOM: TCNTn = 1
 *   OCFnx in phase correct PWM: TCNTn = OCRnx + 1 up, OCRnx - 1 down.
 *
 * Results, one array per timer (t0, t1, t2, t3, t4, t5), in this order:
 *   [0] Normal, OCRnA = 5, OCFnA                 expect 6
 *   [1] Normal, TCNTn = MAX - 2, TOVn             expect 0
 *   [2] CTC, OCRnA = 5, OCFnA                     expect 0
 *   [3] fast PWM, TOP = 9, TOVn                   expect 0
 *   [4] phase correct, TOP = 9, ICFn/OCFnA (TOP)  expect 8
 *   [5] phase correct, TOP = 9, TOVn              expect 1
 *   [6] phase correct, OCRnB = 3, OCFnB up        expect 4
 *   [7] phase correct, OCRnB = 3, OCFnB down      expect 2
 *   [8] flags with TOVn in [3]: TOVn | (ICFn or OCFnA as TOP)
 * 16-bit timers: fast PWM mode 14 / phase correct mode 10, TOP = ICR1 = 9.
 * 8-bit timers: modes 7 / 5, TOP = OCRnA = 9. The ATmega32's Timer0/2 have
 * neither: [3] uses mode 3 (TOP 0xFF), [5] mode 1 (TOP 0xFF), both from
 * TCNTn = 0xF0; [4], [6], [7], [8] are not measured there (0xFF).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint16_t t0[9], t1[9], t2[9], t3[9], t4[9], t5[9];
volatile uint8_t done;

#define WAIT(flags, bit)              \
    do {                              \
        while (!((flags) & _BV(bit))) { \
        }                             \
    } while (0)

/* A 16-bit timer n; flags: its TIFR; r: result array. clk/1024 = CS12|CS10. */
#define SEQ16(n, flags, r)                                                          \
    do {                                                                            \
        TCCR##n##B = 0;                                                             \
        TCCR##n##A = 0;                                                             \
        OCR##n##A = 5;                                                              \
        TCNT##n = 0;                                                                \
        flags = 0xFF;                                                               \
        TCCR##n##B = _BV(CS##n##2) | _BV(CS##n##0);                                 \
        WAIT(flags, OCF##n##A);                                                     \
        r[0] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0xFFFD;                                                           \
        flags = 0xFF;                                                               \
        TCCR##n##B = _BV(CS##n##2) | _BV(CS##n##0);                                 \
        WAIT(flags, TOV##n);                                                        \
        r[1] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0;                                                                \
        flags = 0xFF;                                                               \
        TCCR##n##B = _BV(WGM##n##2) | _BV(CS##n##2) | _BV(CS##n##0); /* mode 4 */   \
        WAIT(flags, OCF##n##A);                                                     \
        r[2] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0;                                                                \
        ICR##n = 9;                                                                 \
        TCCR##n##A = _BV(WGM##n##1);                                                \
        flags = 0xFF;                                                               \
        TCCR##n##B = _BV(WGM##n##3) | _BV(WGM##n##2) | _BV(CS##n##2) | _BV(CS##n##0); /* 14 */ \
        WAIT(flags, TOV##n);                                                        \
        r[3] = TCNT##n;                                                             \
        r[8] = flags & (_BV(TOV##n) | _BV(ICF##n));                                 \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0;                                                                \
        OCR##n##B = 3;                                                              \
        flags = 0xFF;                                                               \
        TCCR##n##B = _BV(WGM##n##3) | _BV(CS##n##2) | _BV(CS##n##0); /* mode 10 */  \
        WAIT(flags, ICF##n);                                                        \
        r[4] = TCNT##n;                                                             \
        flags = 0xFF;                                                               \
        WAIT(flags, TOV##n);                                                        \
        r[5] = TCNT##n;                                                             \
        flags = 0xFF;                                                               \
        WAIT(flags, OCF##n##B);                                                     \
        r[6] = TCNT##n;                                                             \
        flags = 0xFF;                                                               \
        WAIT(flags, OCF##n##B);                                                     \
        r[7] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
    } while (0)

#if TMR_MODERN
/* An 8-bit timer n with TCCRnA/B; cs: its clk/1024 bits. */
#define SEQ8(n, cs, r)                                                              \
    do {                                                                            \
        TCCR##n##B = 0;                                                             \
        TCCR##n##A = 0;                                                             \
        OCR##n##A = 5;                                                              \
        TCNT##n = 0;                                                                \
        TIFR##n = 0xFF;                                                             \
        TCCR##n##B = (cs);                                                          \
        WAIT(TIFR##n, OCF##n##A);                                                   \
        r[0] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0xFD;                                                             \
        TIFR##n = 0xFF;                                                             \
        TCCR##n##B = (cs);                                                          \
        WAIT(TIFR##n, TOV##n);                                                      \
        r[1] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0;                                                                \
        TCCR##n##A = _BV(WGM##n##1); /* mode 2 */                                   \
        TIFR##n = 0xFF;                                                             \
        TCCR##n##B = (cs);                                                          \
        WAIT(TIFR##n, OCF##n##A);                                                   \
        r[2] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0;                                                                \
        OCR##n##A = 9;                                                              \
        TCCR##n##A = _BV(WGM##n##1) | _BV(WGM##n##0);                               \
        TIFR##n = 0xFF;                                                             \
        TCCR##n##B = _BV(WGM##n##2) | (cs); /* mode 7 */                            \
        WAIT(TIFR##n, TOV##n);                                                      \
        r[3] = TCNT##n;                                                             \
        r[8] = TIFR##n & (_BV(TOV##n) | _BV(OCF##n##A));                            \
        TCCR##n##B = 0;                                                             \
        TCNT##n = 0;                                                                \
        OCR##n##B = 3;                                                              \
        TCCR##n##A = _BV(WGM##n##0);                                                \
        TIFR##n = 0xFF;                                                             \
        TCCR##n##B = _BV(WGM##n##2) | (cs); /* mode 5 */                            \
        WAIT(TIFR##n, OCF##n##A);                                                   \
        r[4] = TCNT##n;                                                             \
        TIFR##n = 0xFF;                                                             \
        WAIT(TIFR##n, TOV##n);                                                      \
        r[5] = TCNT##n;                                                             \
        TIFR##n = 0xFF;                                                             \
        WAIT(TIFR##n, OCF##n##B);                                                   \
        r[6] = TCNT##n;                                                             \
        TIFR##n = 0xFF;                                                             \
        WAIT(TIFR##n, OCF##n##B);                                                   \
        r[7] = TCNT##n;                                                             \
        TCCR##n##B = 0;                                                             \
    } while (0)
#else
/* ATmega32 Timer0/2: TCCRn holds everything; one compare unit; only modes 0-3. */
#define SEQ8(n, cs, r)                                                              \
    do {                                                                            \
        TCCR##n = 0;                                                                \
        OCR##n = 5;                                                                 \
        TCNT##n = 0;                                                                \
        TIFR = 0xFF;                                                                \
        TCCR##n = (cs);                                                             \
        WAIT(TIFR, OCF##n);                                                         \
        r[0] = TCNT##n;                                                             \
        TCCR##n = 0;                                                                \
        TCNT##n = 0xFD;                                                             \
        TIFR = 0xFF;                                                                \
        TCCR##n = (cs);                                                             \
        WAIT(TIFR, TOV##n);                                                         \
        r[1] = TCNT##n;                                                             \
        TCCR##n = 0;                                                                \
        TCNT##n = 0;                                                                \
        TIFR = 0xFF;                                                                \
        TCCR##n = _BV(WGM##n##1) | (cs);                                            \
        WAIT(TIFR, OCF##n);                                                         \
        r[2] = TCNT##n;                                                             \
        TCCR##n = 0;                                                                \
        TCNT##n = 0xF0;                                                             \
        TIFR = 0xFF;                                                                \
        TCCR##n = _BV(WGM##n##1) | _BV(WGM##n##0) | (cs);                           \
        WAIT(TIFR, TOV##n);                                                         \
        r[3] = TCNT##n;                                                             \
        TCCR##n = 0;                                                                \
        TCNT##n = 0xF0;                                                             \
        TIFR = 0xFF;                                                                \
        TCCR##n = _BV(WGM##n##0) | (cs);                                            \
        WAIT(TIFR, TOV##n);                                                         \
        r[5] = TCNT##n;                                                             \
        TCCR##n = 0;                                                                \
        r[4] = r[6] = r[7] = r[8] = 0xFF;                                           \
    } while (0)
#endif

int main(void)
{
#if TMR_MODERN
    SEQ16(1, TIFR1, t1);
    SEQ8(0, _BV(CS02) | _BV(CS00), t0);
    SEQ8(2, _BV(CS22) | _BV(CS21) | _BV(CS20), t2);
#if TMR_SIX
    SEQ16(3, TIFR3, t3);
    SEQ16(4, TIFR4, t4);
    SEQ16(5, TIFR5, t5);
#endif
#else
    SEQ16(1, TIFR, t1);
    SEQ8(0, _BV(CS02) | _BV(CS00), t0);
    SEQ8(2, _BV(CS22) | _BV(CS21) | _BV(CS20), t2);
#endif
    done = 1;
    for (;;) {
    }
}
