/*
 * afstepper.h - the stepper half of the Adafruit Motor Shield v1 library
 * (AFMotor.cpp, as seed 003 quotes it in §3.x and its digest §2.3-2.5),
 * in C, for a stepper on port 2 (terminals M3 + M4) of the shield.
 *
 * Pins (AFMotor.h): 74HC595 DIR_SER = PB0 (D8), DIR_CLK = PD4 (D4),
 * DIR_LATCH = PB4 (D12), DIR_EN = PD7 (D7, active low). Port 2's bridges are
 * enabled by PD6 (D6, OC0A) and PD5 (D5, OC0B); at setPWM(255) those pins are
 * constantly high, so here they are plain outputs driven high.
 *
 * Shift-register bits: MOTOR3_A 5 (A+), MOTOR4_A 0 (B+), MOTOR3_B 7 (A-),
 * MOTOR4_B 6 (B-); onestep()'s a, b, c, d.
 *
 * onestep() keeps AFMotor's `currentstep` bookkeeping (0..63, MICROSTEPS =
 * 16, eight half-step slots of 8): SINGLE lands on even slots (A+, B+, A-, B-
 * = slots 0, 2, 4, 6), DOUBLE on odd ones (A+B+, B+A-, A-B-, B-A+), INTERLEAVE
 * on all. On a fresh object the first DOUBLE FORWARD step gives A+B+ and the
 * first SINGLE FORWARD step gives B+ (AFMotor's quirk, digest §3.1).
 *
 * latch_tx() shifts latch_state out MSB first, as AFMotor's does. With
 * AFSTEPPER_ARDUINO_IO defined every pin write goes through digital_write(),
 * which costs about what Arduino's digitalWrite() does (a table lookup and an
 * interrupt-safe read-modify-write, ~60 cycles): the thesis firmware's step
 * takes as long as it did on the Arduino. Otherwise the writes are single
 * SBI/CBI instructions.
 */
#ifndef AFSTEPPER_H
#define AFSTEPPER_H

#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>

#define FORWARD 1
#define BACKWARD 2
#define SINGLE 1
#define DOUBLE 2
#define INTERLEAVE 3
#define MICROSTEP 4 /* with AFSTEPPER_MICROSTEP defined: PWM on the bridge enables */

#define MICROSTEPS 16

#define MOTOR3_A 5
#define MOTOR3_B 7
#define MOTOR4_A 0
#define MOTOR4_B 6

static uint8_t latch_state;
static uint8_t currentstep;

#ifdef AFSTEPPER_ARDUINO_IO
/* Arduino digitalWrite()'s work: pin -> port and mask lookups, then the
 * read-modify-write with interrupts off. The lookups are volatile reads so
 * the compiler keeps them. */
static volatile uint8_t *const af_port_of[4] = {&PORTB, &PORTD, &PORTB, &PORTD};
static volatile uint8_t af_mask_of[4] = {_BV(PB0), _BV(PD4), _BV(PB4), _BV(PD7)};
#define AF_SER 0
#define AF_CLK 1
#define AF_LATCH 2
#define AF_EN 3
static void __attribute__((noinline, unused)) digital_write(uint8_t pin, uint8_t value)
{
    volatile uint8_t *port = af_port_of[pin];
    uint8_t mask = af_mask_of[pin];
    uint8_t sreg = SREG;
    cli();
    if (value) *port |= mask;
    else *port &= (uint8_t)~mask;
    SREG = sreg;
}
#define AF_WRITE(pin, value) digital_write(AF_##pin, (value) != 0)
#else
#define AF_SER_PORT PORTB
#define AF_SER_BIT PB0
#define AF_CLK_PORT PORTD
#define AF_CLK_BIT PD4
#define AF_LATCH_PORT PORTB
#define AF_LATCH_BIT PB4
#define AF_EN_PORT PORTD
#define AF_EN_BIT PD7
#define AF_WRITE(pin, value)                                                   \
    do {                                                                       \
        if (value) AF_##pin##_PORT |= _BV(AF_##pin##_BIT);                     \
        else AF_##pin##_PORT &= (uint8_t)~_BV(AF_##pin##_BIT);                 \
    } while (0)
#endif

static inline void latch_tx(void)
{
    uint8_t i;
    AF_WRITE(LATCH, 0);
    AF_WRITE(SER, 0);
    for (i = 0; i < 8; i++) {
        AF_WRITE(CLK, 0);
        AF_WRITE(SER, latch_state & _BV(7 - i));
        AF_WRITE(CLK, 1);
    }
    AF_WRITE(LATCH, 1);
}

/* AFMotorController::enable() + AF_Stepper(200, 2)'s constructor. */
static inline void afstepper_init(void)
{
    DDRB |= _BV(PB0) | _BV(PB4);
    DDRD |= _BV(PD4) | _BV(PD7) | _BV(PD5) | _BV(PD6);
    latch_state = 0;
    latch_tx();
    AF_WRITE(EN, 0); /* outputs of the 74HC595 on */
    PORTD |= _BV(PD5) | _BV(PD6); /* both bridges of port 2 enabled (setPWM 255) */
    currentstep = 0;
}

static inline void afstepper_release(void)
{
    latch_state &= (uint8_t)(~_BV(MOTOR3_A) & ~_BV(MOTOR3_B) & ~_BV(MOTOR4_A) & ~_BV(MOTOR4_B));
    latch_tx();
}

#ifdef AFSTEPPER_MICROSTEP
/* AFMotor's microstep duty curve (digest §2.5), MICROSTEPS + 1 entries. */
static const uint8_t microstep_curve[MICROSTEPS + 1] = {0,   25,  50,  74,  98,  120, 141, 162, 180,
                                                        197, 212, 225, 236, 244, 250, 253, 255};

/* Port 2's bridge enables as Timer0 PWM (OC0A = PD6 -> phase A's 1,2EN,
 * OC0B = PD5 -> phase B's 3,4EN), fast PWM at clk/64 (976.6 Hz: AFMotor
 * leaves Timer0's prescaler at the Arduino default for port 2, digest §2.5),
 * or constantly high for the full-step styles (setPWM(255)). */
static inline void afstepper_pwm(uint8_t on)
{
    if (on) {
        TCCR0A = _BV(COM0A1) | _BV(COM0B1) | _BV(WGM01) | _BV(WGM00);
        TCCR0B = _BV(CS01) | _BV(CS00);
    } else {
        TCCR0A = 0;
        TCCR0B = 0;
        PORTD |= _BV(PD5) | _BV(PD6);
    }
}

/* One microstep: currentstep moves by 1 of 64 per electrical cycle. In
 * quadrant q (16 microsteps each) the coil pair a|b, b|c, c|d, d|a carries
 * current; within it the duties follow the curve, one phase falling as the
 * other rises (duty_A = curve[16 - k], duty_B = curve[k] in the first). */
static inline void afstepper_microstep(uint8_t dir)
{
    const uint8_t a = _BV(MOTOR3_A), b = _BV(MOTOR4_A), c = _BV(MOTOR3_B), d = _BV(MOTOR4_B);
    if (dir == FORWARD) currentstep++;
    else currentstep--;
    currentstep += MICROSTEPS * 4;
    currentstep %= MICROSTEPS * 4;
    const uint8_t quadrant = currentstep / MICROSTEPS, k = currentstep % MICROSTEPS;
    /* Phase A's duty rises in odd quadrants and falls in even ones; B the reverse. */
    const uint8_t rising = microstep_curve[k], falling = microstep_curve[MICROSTEPS - k];
    OCR0A = (quadrant % 2) ? rising : falling;
    OCR0B = (quadrant % 2) ? falling : rising;
    latch_state &= (uint8_t)(~a & ~b & ~c & ~d);
    switch (quadrant) {
        case 0: latch_state |= a | b; break;
        case 1: latch_state |= b | c; break;
        case 2: latch_state |= c | d; break;
        default: latch_state |= d | a; break;
    }
    latch_tx();
}
#endif

static inline uint8_t afstepper_onestep(uint8_t dir, uint8_t style)
{
    const uint8_t a = _BV(MOTOR3_A), b = _BV(MOTOR4_A), c = _BV(MOTOR3_B), d = _BV(MOTOR4_B);
    if (style == SINGLE) {
        if ((currentstep / (MICROSTEPS / 2)) % 2) { /* odd: go to the next even slot */
            if (dir == FORWARD) currentstep += MICROSTEPS / 2;
            else currentstep -= MICROSTEPS / 2;
        } else {
            if (dir == FORWARD) currentstep += MICROSTEPS;
            else currentstep -= MICROSTEPS;
        }
    } else if (style == DOUBLE) {
        if (!((currentstep / (MICROSTEPS / 2)) % 2)) { /* even: go to the next odd slot */
            if (dir == FORWARD) currentstep += MICROSTEPS / 2;
            else currentstep -= MICROSTEPS / 2;
        } else {
            if (dir == FORWARD) currentstep += MICROSTEPS;
            else currentstep -= MICROSTEPS;
        }
    } else { /* INTERLEAVE */
        if (dir == FORWARD) currentstep += MICROSTEPS / 2;
        else currentstep -= MICROSTEPS / 2;
    }
    currentstep += MICROSTEPS * 4;
    currentstep %= MICROSTEPS * 4;

    latch_state &= (uint8_t)(~a & ~b & ~c & ~d);
    switch (currentstep / (MICROSTEPS / 2)) {
        case 0: latch_state |= a; break;     /* A+ */
        case 1: latch_state |= a | b; break; /* A+ B+ */
        case 2: latch_state |= b; break;     /* B+ */
        case 3: latch_state |= b | c; break; /* B+ A- */
        case 4: latch_state |= c; break;     /* A- */
        case 5: latch_state |= c | d; break; /* A- B- */
        case 6: latch_state |= d; break;     /* B- */
        case 7: latch_state |= d | a; break; /* B- A+ */
    }
    latch_tx();
    return currentstep;
}

#endif /* AFSTEPPER_H */
