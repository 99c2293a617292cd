/*
 * tmr_com_port - the OC1A pin against its PORT and DDR bits; FOC1A.
 *
 * Datasheet (ATmega328P §16.8 "Compare Match Output Unit", §15.6 for
 * Timer0): "The general I/O port function is overridden by the Output Compare
 * (OC1x) from the Waveform Generator if either of the COM1x1:0 bits are set.
 * However, the OC1x pin direction (input or output) is still controlled by
 * the Data Direction Register (DDR) for the port pin. The Data Direction
 * Register bit for the OC1x pin (DDR_OC1x) must be set as output before the
 * OC1x value is visible on the pin." The PORT register is left alone: when
 * COM1x1:0 is cleared the pin shows PORT again. §16.7.1 "Force Output
 * Compare": in non-PWM modes writing FOC1x updates OC1x "as if a real Compare
 * Match had occurred", without setting OCF1x.
 *
 * OC1A: PB1 (328P), PB5 (2560), PD5 (m32). Timer1 CTC, clk/1, OCR1A = 99,
 * COM1A = 01: OC1A toggles every 100 cycles. Marker 0 (PC0 / PF0) toggles at
 * the start of each phase; each phase lasts about 1200 cycles.
 *   1: DDR = 1, PORT bit = 0. The firmware keeps writing the port register
 *      (other bits) and samples it: `port_or` (PORT bit ever 1?) must stay 0;
 *      `pin_seen` gets bit 0 / bit 1 for PIN bit read 0 / 1 (both: 3).
 *   2: PORT bit = 1 (COM still 01): the pin still toggles every 100;
 *      `port_p2` = PORT bit read back (1).
 *   3: COM1A = 00: the pin shows PORT = 1, no more toggles.
 *   4: COM1A = 01 again, DDR bit = 0: an input with the pull-up (PORT = 1),
 *      OC1A not visible: high, no toggles; `pin_p4` = PIN bit reads (bits as
 *      in pin_seen: 2 = only ones).
 *   5: DDR bit = 1: the pin toggles again.
 *   6: timer stopped; COM1A = 10 + FOC1A (OC1A low), marker, COM1A = 11 +
 *      FOC1A (high at once), marker, COM1A = 10 + FOC1A (low at once);
 *      `ocf_p6` = OCF1A after the strobes (0: FOC sets no flag).
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

#if defined(__AVR_ATmega328P__)
#define OC_PORT PORTB
#define OC_PIN PINB
#define OC_DDR DDRB
#define OC_BIT 1
#define OTHER_BIT 4
#elif defined(__AVR_ATmega2560__)
#define OC_PORT PORTB
#define OC_PIN PINB
#define OC_DDR DDRB
#define OC_BIT 5
#define OTHER_BIT 0
#else
#define OC_PORT PORTD
#define OC_PIN PIND
#define OC_DDR DDRD
#define OC_BIT 5
#define OTHER_BIT 0
#endif

#if TMR_MODERN
#define FLAGS1 TIFR1
#define STROBE_A() (TCCR1C = _BV(FOC1A))
#define COM_A(bits) (TCCR1A = (bits))
#else
#define FLAGS1 TIFR
/* ATmega32: FOC1A lives in TCCR1A with the COM bits. */
#define STROBE_A() (TCCR1A = TCCR1A | _BV(FOC1A))
#define COM_A(bits) (TCCR1A = (bits))
#endif

volatile uint8_t port_or, pin_seen, port_p2, pin_p4, ocf_p6;
volatile uint8_t done;

/* About 1200 cycles of sampling and port writes. */
static void sample(volatile uint8_t* port_acc, volatile uint8_t* pin_acc)
{
    for (uint8_t i = 0; i < 60; ++i) {
        OC_PORT ^= _BV(OTHER_BIT);
        const uint8_t p = OC_PORT;
        const uint8_t q = OC_PIN;
        if (port_acc) *port_acc |= (p & _BV(OC_BIT)) ? 1 : 0;
        if (pin_acc) *pin_acc |= (q & _BV(OC_BIT)) ? 2 : 1;
    }
}

int main(void)
{
    MARK_DDR = 0x0F;
    OC_DDR = _BV(OC_BIT) | _BV(OTHER_BIT);
    OCR1A = 99;
    COM_A(_BV(COM1A0));
    TCCR1B = _BV(WGM12) | _BV(CS10);

    MARK_TOGGLE(0); /* phase 1 */
    sample(&port_or, &pin_seen);

    MARK_TOGGLE(0); /* phase 2 */
    OC_PORT |= _BV(OC_BIT);
    port_p2 = (OC_PORT & _BV(OC_BIT)) ? 1 : 0;
    sample(0, 0);

    MARK_TOGGLE(0); /* phase 3 */
    COM_A(0);
    sample(0, 0);

    MARK_TOGGLE(0); /* phase 4 */
    OC_DDR &= (uint8_t)~_BV(OC_BIT);
    COM_A(_BV(COM1A0));
    sample(0, &pin_p4);

    MARK_TOGGLE(0); /* phase 5 */
    OC_DDR |= _BV(OC_BIT);
    sample(0, 0);

    MARK_TOGGLE(0); /* phase 6 */
    TCCR1B = _BV(WGM12);
    FLAGS1 = _BV(OCF1A);
    COM_A(_BV(COM1A1));
    STROBE_A();
    __builtin_avr_delay_cycles(200);
    MARK_TOGGLE(1);
    COM_A(_BV(COM1A1) | _BV(COM1A0));
    STROBE_A();
    __builtin_avr_delay_cycles(200);
    MARK_TOGGLE(1);
    COM_A(_BV(COM1A1));
    STROBE_A();
    ocf_p6 = (FLAGS1 & _BV(OCF1A)) ? 1 : 0;
    done = 1;
    for (;;) {
    }
}
