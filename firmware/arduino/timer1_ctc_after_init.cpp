// The Marlin 1.x stepper-timer pattern on the Arduino core: init() leaves
// Timer1 in 8-bit phase-correct PWM at clk/64 (wiring.c); the sketch then
// switches it to CTC (WGM12 set, WGM10 cleared) at clk/8 with OCR1A = 1999,
// a compare-match interrupt every 2000 x 8 cycles = 1 ms, without touching
// TCNT1. It does so at 8 points of the PWM period (510 x 64 cycles =
// 2.04 ms), each time counting the COMPA interrupts in the next 20 ms (20
// expected: at most one period is lost to the counter starting above OCR1A),
// then restores init()'s state (TCNT1 from 0, PWM mode). Serial prints the
// eight counts.
#include <Arduino.h>

volatile uint16_t matches;
ISR(TIMER1_COMPA_vect) { ++matches; }

void setup() {
    Serial.begin(115200);
    for (uint8_t phase = 0; phase < 8; ++phase) {
        delayMicroseconds(2040u * phase / 8 + 10);
        noInterrupts();
        TCCR1B |= _BV(WGM12);                // as Marlin's HAL_timer_start: CTC ...
        TCCR1A &= ~(_BV(WGM11) | _BV(WGM10));
        TCCR1B = (TCCR1B & ~0x07) | _BV(CS11);  // ... at clk/8
        OCR1A = 1999;
        matches = 0;
        TIFR1 = _BV(OCF1A);
        TIMSK1 |= _BV(OCIE1A);
        interrupts();
        delay(20);
        TIMSK1 &= ~_BV(OCIE1A);
        Serial.print(matches);
        Serial.print(phase == 7 ? '\n' : ' ');
        // Back to init()'s state: stopped, TCNT1 = 0 (as after reset), then
        // phase-correct 8-bit PWM at clk/64 as wiring.c sets it.
        TCCR1B = 0;
        TCNT1 = 0;
        TCCR1B = _BV(CS11) | _BV(CS10);
        TCCR1A = _BV(WGM10);
    }
}

void loop() {}
