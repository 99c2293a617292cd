/*
 * blink - PB5 (the UNO's LED) toggles every 50 ms from the Timer1 compare-A
 * interrupt; "ready\n" goes out on USART0 at 9600 baud once at start.
 *
 * Timer1, CTC mode 4 (WGM12), prescaler 64: f = 16 MHz / 64 = 250 kHz;
 * OCR1A = 12499 gives a compare match every 12500 ticks = 50 ms.
 * USART0: UBRR0 = 16e6 / (16 * 9600) - 1 = 103.2 -> 103 (datasheet table: 0.2 % error).
 */
#include <avr/interrupt.h>
#include <avr/io.h>

ISR(TIMER1_COMPA_vect) { PINB = _BV(PB5); }  /* writing 1 to PINx toggles PORTx */

static void send(const char *text) {
    for (; *text != '\0'; ++text) {
        loop_until_bit_is_set(UCSR0A, UDRE0);
        UDR0 = (uint8_t)*text;
    }
}

int main(void) {
    DDRB = _BV(PB5);
    UBRR0 = 103;
    UCSR0B = _BV(TXEN0);
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    send("ready\n");
    OCR1A = 12499;
    TCCR1B = _BV(WGM12) | _BV(CS11) | _BV(CS10);
    TIMSK1 = _BV(OCIE1A);
    sei();
    for (;;) {
    }
}
