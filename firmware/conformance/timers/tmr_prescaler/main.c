/*
 * tmr_prescaler - the shared, free-running prescaler of Timer/Counter0 and 1
 * (and 3, 4, 5 on the 2560); prescaler reset and synchronization mode.
 *
 * Datasheet (ATmega328P §17.1 "Internal Clock Source", §17.2 "Prescaler
 * Reset", §17.4.1 GTCCR; ATmega2560 §18; ATmega32 "Timer/Counter0 and
 * Timer/Counter1 Prescalers", SFIOR): "The prescaler is free running, i.e.,
 * operates independently of the Clock Select logic of the Timer/Counter, and
 * it is shared by Timer/Counter1 and Timer/Counter0." "The number of system
 * clock cycles from when the timer is enabled to the first count occurs can be
 * from 1 to N+1 system clock cycles". "It is possible to use the prescaler
 * reset for synchronizing the Timer/Counter to program execution." With TSM =
 * 1 "the value that is written to the PSRASY and PSRSYNC bits is kept, hence
 * keeping the corresponding prescaler reset signals asserted", so the timers
 * can be configured and then started at the same time.
 *
 * A: Timer1 CTC, clk/64, OCR1A = 9, OC1A toggling; 13 cycles later Timer0
 *    CTC, clk/64, OCR0A = 4, OC0A toggling, for 10000 cycles. Both count on the same
 *    prescaler output: every edge of either falls on the same phase mod 64.
 * B: both stopped, TCNT1 = 0, OCR1A = 1; marker 2 toggles (OUT) and on the
 *    next instruction (OUT) the prescaler is reset (PSRSYNC; PSR10 on the
 *    ATmega32); 100 cycles later Timer1 starts: CTC, clk/1024. Its clocks come
 *    1024, 2048, ... cycles after the reset; the second leaves TCNT1 = OCR1A:
 *    the first OC1A toggle is 1 + 2 * 1024 = 2049 cycles after the marker edge.
 *    (OCR1A = 0 would not do: the TCNT1 write blocks the compare match of the
 *    first clock, §16.7.2.)
 * C: (328P, 2560) TSM = 1 with PSRSYNC: prescaler held; Timer1 (CTC OCR1A = 9)
 *    and Timer0 (CTC OCR0A = 9) get clk/8 at different times; then marker 3
 *    and on the next instruction GTCCR = 0: both toggle first 1 + 10 * 8 = 81
 *    cycles after the marker edge.
 * OC1A/OC0A: PB1/PD6 (328P), PB5/PB7 (2560), PD5/PB3 (ATmega32).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t phase;

#if TMR_MODERN
#define PRESCALER_RESET GTCCR
#define SYNC_RESET PSRSYNC
#else
#define PRESCALER_RESET SFIOR
#define SYNC_RESET PSR10
#endif

/* Two OUTs back to back: the marker edge, then `value` to the prescaler register. */
#define MARK_THEN(bit, value)                                                              \
    __asm__ __volatile__("out %0, %2\n\tout %1, %3" ::"I"(_SFR_IO_ADDR(MARK_PIN_OUT)),       \
                         "I"(_SFR_IO_ADDR(PRESCALER_RESET)), "r"((uint8_t)_BV(bit)), "r"((uint8_t)(value)))

#if TMR_MODERN
#define MARK_PIN_OUT MARK_PIN /* a one written to PINxn toggles the pin */
#else
#define MARK_PIN_OUT MARK_PORT
#endif

int main(void)
{
    tmr_oc_outputs();
    MARK_PORT = 0;
    /* A */
    OCR1A = 9;
    TCCR1A = _BV(COM1A0);
    TCCR1B = _BV(WGM12) | _BV(CS11) | _BV(CS10);
    __builtin_avr_delay_cycles(13);
#if TMR_MODERN
    OCR0A = 4;
    TCCR0A = _BV(COM0A0) | _BV(WGM01);
    TCCR0B = _BV(CS01) | _BV(CS00);
#else
    OCR0 = 4;
    TCCR0 = _BV(WGM01) | _BV(COM00) | _BV(CS01) | _BV(CS00);
#endif
    __builtin_avr_delay_cycles(10000);
    phase = 1;

    /* B */
#if TMR_MODERN
    TCCR0B = 0;
#else
    TCCR0 = _BV(WGM01) | _BV(COM00); /* clock off, OC0 still connected */
#endif
    TCCR1B = _BV(WGM12);
    OCR1A = 1;
    TCNT1 = 0;
    MARK_THEN(2, _BV(SYNC_RESET));
    __builtin_avr_delay_cycles(100);
    TCCR1B = _BV(WGM12) | _BV(CS12) | _BV(CS10);
    __builtin_avr_delay_cycles(5000);
    TCCR1B = _BV(WGM12);
    phase = 2;

#if TMR_MODERN
    /* C */
    GTCCR = _BV(TSM) | _BV(PSRSYNC);
    OCR1A = 9;
    TCNT1 = 0;
    OCR0A = 9;
    TCNT0 = 0;
    TCCR1B = _BV(WGM12) | _BV(CS11);
    __builtin_avr_delay_cycles(37);
    TCCR0B = _BV(CS01);
    __builtin_avr_delay_cycles(50);
    MARK_THEN(3, 0);
    __builtin_avr_delay_cycles(500);
    phase = 3;
#endif
    for (;;) {
    }
}
