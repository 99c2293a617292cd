/*
 * irq_sei_raise - an interrupt whose flag is set while SEI executes is served
 * after the instruction that follows SEI, and a pending interrupt is served
 * after every later `sei; nop`.
 *
 * ATmega328P §7.7, ATmega2560 §7.8, ATmega32 "Interrupt Response Time": when
 * SEI sets I, "the instruction following SEI will be executed before any
 * pending interrupts"; an enabled interrupt whose flag is set is served as
 * soon as I is one and the current instruction (here the one after SEI) has
 * completed. The "irq_wait" idiom `sei; nop; cli` relies on it.
 *
 * Timer1 in Normal mode at clk/1 with OCR1A = 20 and OCIE1A set raises its
 * compare-match interrupt a fixed number of cycles after TCNT1 is cleared,
 * once: the next match is 65536 cycles later. (In CTC mode it would match
 * again every 21 cycles, and the ISR takes 42 cycles from the match to the
 * store that stops the timer: a second match would be pending when it
 * returns, and rightly served in the next window.)
 * For each delay k = 0..23 cycles the firmware, with interrupts off, clears
 * TCNT1 and OCF1A, starts the timer, waits k cycles, then runs
 *
 *     sei ; nop ; cli        (window 1)
 *     sei ; nop ; cli        (window 2)
 *     100 cycles with I = 0  (the match has surely happened by then)
 *     sei ; nop ; cli        (window 3)
 *
 * Across k the match lands after, inside and before the first windows,
 * including on an SEI itself. The ISR stops the timer, so it runs at most
 * once; `served[k]` counts its runs and `window[k]` says in which window it
 * ran. Expected for every k: served = 1 (a pending interrupt is served after
 * the `nop` of the next window at the latest), and window[k] does not grow
 * with k (a later window start can only see the match earlier).
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "avrbench_mcu.h"

AVRBENCH_MCU_SECTION();

#if defined(TIMSK1)
#define TIMSK_T1 TIMSK1
#define TIFR_T1 TIFR1
#else
#define TIMSK_T1 TIMSK
#define TIFR_T1 TIFR
#endif

#define ATTEMPTS 24
volatile uint8_t served[ATTEMPTS];
volatile uint8_t window[ATTEMPTS];
volatile uint8_t current;      /* the attempt in progress */
volatile uint8_t in_window;    /* 1 or 2 while the main line is in that window */
volatile uint8_t done;

ISR(TIMER1_COMPA_vect)
{
    served[current]++;
    window[current] = in_window;
    TCCR1B = 0; /* one match per attempt */
}

#define ATTEMPT(k)                                                        \
    do {                                                                  \
        current = (k);                                                    \
        TCCR1B = 0;                                                       \
        TCNT1 = 0;                                                        \
        TIFR_T1 = _BV(OCF1A);                                             \
        TCCR1B = _BV(CS10);                                               \
        __builtin_avr_delay_cycles((k) + 1);                              \
        in_window = 1;                                                    \
        __asm__ __volatile__("sei\n\tnop\n\tcli" ::: "memory");          \
        in_window = 2;                                                    \
        __asm__ __volatile__("sei\n\tnop\n\tcli" ::: "memory");          \
        in_window = 0;                                                    \
        __builtin_avr_delay_cycles(100);                                  \
        in_window = 3;                                                    \
        __asm__ __volatile__("sei\n\tnop\n\tcli" ::: "memory");          \
        in_window = 0;                                                    \
        TCCR1B = 0;                                                       \
    } while (0)

int main(void)
{
    OCR1A = 20;
    TCCR1A = 0;
    TIMSK_T1 = _BV(OCIE1A);
    ATTEMPT(0); ATTEMPT(1); ATTEMPT(2); ATTEMPT(3); ATTEMPT(4); ATTEMPT(5);
    ATTEMPT(6); ATTEMPT(7); ATTEMPT(8); ATTEMPT(9); ATTEMPT(10); ATTEMPT(11);
    ATTEMPT(12); ATTEMPT(13); ATTEMPT(14); ATTEMPT(15); ATTEMPT(16); ATTEMPT(17);
    ATTEMPT(18); ATTEMPT(19); ATTEMPT(20); ATTEMPT(21); ATTEMPT(22); ATTEMPT(23);
    done = 1;
    for (;;) {
    }
}
