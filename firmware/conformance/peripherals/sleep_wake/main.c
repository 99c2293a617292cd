/*
 * sleep_wake - SLEEP, SE and waking up.
 *
 * ATmega328P §10.1 and §7.7.1 (2560 §11.1 and §7.8.1; m32 "Power Management
 * and Sleep Modes", "Interrupt Response Time"):
 *   - "To enter any of the sleep modes, the SE bit in SMCR must be written
 *     to logic one and a SLEEP instruction must be executed": with SE = 0,
 *     SLEEP does nothing (1 cycle).
 *   - "If an interrupt occurs when the MCU is in sleep mode, the interrupt
 *     execution response time is increased by four clock cycles [five on the
 *     2560]. This increase comes in addition to the start-up time from the
 *     selected sleep mode." Idle keeps the clock running (no start-up time);
 *     from Power-down the start-up time is the one the CKSEL/SUT fuses select
 *     (this ELF's .fuse section: low fuse 0xFF, 16K CK, §9.2 Table 9-4).
 *   - "the instruction following SEI will be executed before any pending
 *     interrupts": `sei ; sleep` sleeps, and the pending interrupt wakes the
 *     part; its ISR runs before the instruction after SLEEP.
 *   - Power-down: INT0/INT1 edges are not detected (no clk_IO), only the low
 *     level wakes the part (§10.1 Table 10-1 note 3).
 *
 * Steps (markers on PORTB; the bench drives INT0 and, in step 4, INT1):
 *  1. `sbi PORTB,0 ; sleep ; cbi PORTB,0` with SE = 0: 2 + 1 cycles apart.
 *  2. INT1 pin as output, rising edge -> INTF1 pending with I = 0; SE = 1, Idle;
 *     `ldi r24,0 ; sei ; sleep ; inc r24 ; ...`; the INT1 ISR stores r24 in
 *     `pending_isr_saw`, copied to `pending_result` (datasheet: 0, the ISR runs
 *     before the inc).
 *  3. Idle, INT0 falling edge enabled; marker PB1; sleep. The bench drives
 *     INT0 low at a chosen cycle; the INT0 ISR's first instruction sets PB2.
 *  4. The bench releases INT0. Power-down with INT0 on falling edge and INT1
 *     (now an input with pull-up) on low level; marker PB3; sleep. The bench
 *     makes a falling edge on INT0 (on the 328P and the m32 it is not
 *     detected: no wake-up; on the 2560 INT3:0 are asynchronous, §15, and it
 *     wakes the part), then drives INT1 low: the level wakes the part and the
 *     INT1 ISR's first instruction sets PB5. Marker PB4 when main resumes.
 * Both ISRs are naked: marker, then EXT_MASK = 0 (no further interrupt).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>

#include "avrbench_mcu.h"
#include "../common/periph.h"

AVRBENCH_MCU_SECTION();

#if defined(__AVR_ATmega32__)
FUSES = {.low = 0xFF, .high = 0xD9};
#elif defined(__AVR_ATmega2560__)
FUSES = {.low = 0xFF, .high = 0xD8, .extended = 0xFD};
#else
FUSES = {.low = 0xFF, .high = 0xDE, .extended = 0xFD};
#endif

volatile uint8_t pending_isr_saw = 0xFF;
volatile uint8_t pending_result = 0xFF;
volatile uint8_t wakeups;

ISR(INT0_vect, ISR_NAKED)
{
    asm volatile("sbi %[portb], 2\n\t"
                 "push r24\n\t"
                 "ldi r24, 0\n\t"
                 "out %[mask], r24\n\t"
                 "pop r24\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB),
                 [mask] "I"(_SFR_IO_ADDR(EXT_MASK)));
}

ISR(INT1_vect, ISR_NAKED)
{
    asm volatile("sbi %[portb], 5\n\t"
                 "sts pending_isr_saw, r24\n\t"
                 "push r24\n\t"
                 "ldi r24, 0\n\t"
                 "out %[mask], r24\n\t"
                 "pop r24\n\t"
                 "reti\n\t" ::[portb] "I"(IO_PORTB),
                 [mask] "I"(_SFR_IO_ADDR(EXT_MASK)));
}

int main(void)
{
    DDRB = 0xFF;
    PORTB = 0;
    PORTD |= (1 << INT0_PIN);
    EXT_MASK = 0;

    /* 1: SE = 0 */
    cli();
    sleep_disable();
    asm volatile("sbi %[portb], 0\n\t"
                 "sleep\n\t"
                 "cbi %[portb], 0\n\t" ::[portb] "I"(IO_PORTB));

    /* 2: sei ; sleep with INT1 pending */
    EXT_SENSE = (1 << ISC11) | (1 << ISC10);
    EXT_FLAGS = (1 << INTF1);
    EXT_MASK = (1 << INT1);
    DDRD |= (1 << INT1_PIN);
    PORTD |= (1 << INT1_PIN);
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    asm volatile("ldi r24, 0\n\t"
                 "sei\n\t"
                 "sleep\n\t"
                 "inc r24\n\t"
                 "inc r24\n\t" ::
                     : "r24");
    cli();
    EXT_MASK = 0;
    pending_result = pending_isr_saw;
    PORTB &= (uint8_t) ~(1 << PB5);

    /* 3: Idle, INT0 falling edge */
    EXT_SENSE = (1 << ISC01);
    EXT_FLAGS = (1 << INTF0);
    EXT_MASK = (1 << INT0);
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable(); /* on the m32 SE shares MCUCR with the sense bits just written */
    PORTB |= (1 << PB1);
    sei();
    sleep_cpu();
    ++wakeups;
    PORTB &= (uint8_t) ~(1 << PB2);

    /* 4: Power-down; INT0 falling edge, INT1 low level */
    while (!(PIND & (1 << INT0_PIN))) {
    }
    cli();
    DDRD &= (uint8_t) ~(1 << INT1_PIN);
    PORTD |= (1 << INT1_PIN);
    EXT_SENSE = (1 << ISC01); /* INT0 falling edge, INT1 low level */
    EXT_FLAGS = (1 << INTF0) | (1 << INTF1);
    set_sleep_mode(SLEEP_MODE_PWR_DOWN);
    sleep_enable();
    PORTB &= (uint8_t) ~(1 << PB5);
    PORTB |= (1 << PB3);
    EXT_MASK = (1 << INT0) | (1 << INT1);
    sei();
    sleep_cpu();
    ++wakeups;
    PORTB |= (1 << PB4);
    for (;;) {
    }
}
