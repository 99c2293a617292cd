/*
 * tmr_tifr - clearing TIFRn flags: by writing ones (OUT), by SBI, CBI, zero.
 *
 * Datasheet (ATmega328P §16.11.9 TIFR1: "OCF1A can be cleared by writing a
 * logic one to its bit location"; §8.5 "I/O Memory":
 * "Some of the Status Flags are cleared by writing a logical one to them.
 * Note that, unlike most other AVRs, the CBI and SBI instructions will only
 * operate on the specified bit, and can therefore be used on registers
 * containing such Status Flags." The ATmega2560 says the same. The ATmega32
 * says the opposite ("the CBI and SBI instructions will operate on all bits in
 * the I/O Register, writing a one back into any flag read as set") but its
 * TIFR (I/O 0x38) is out of their reach anyway: `TIFR |= x` there is IN, ORI,
 * OUT, which writes a one to every flag that is set.
 *
 * Timer1 runs in Normal mode at clk/1 from TCNT1 = 0xFF00 with OCR1A = 100,
 * OCR1B = 200 for 700 cycles and stops: TOV1, OCF1A, OCF1B are set. Then
 * `r[]` records TIFR1 (TIFR & 0x1C on the ATmega32) after each step:
 *   [0] as set                 328P/2560: 0x07      m32: 0x1C
 *   [1] TIFR1 = _BV(OCF1A)      OUT        0x05            0x0C
 *   [2] TIFR1 |= _BV(TOV1)      SBI        0x04  (m32: IN/ORI/OUT: 0x00)
 *   [3] TIFR1 &= ~_BV(OCF1B)    CBI        0x04            0x00
 *   [4] TIFR1 = 0               OUT        0x04            0x00
 *   then all three set again:
 *   [5]                                    0x07            0x1C
 *   [6] TIFR1 = TIFR1 (read, write back)   0x00            0x00
 * (328P/2560 TIFR1: ICF1 5, OCF1B 2, OCF1A 1, TOV1 0; ATmega32 TIFR: OCF1A 4,
 * OCF1B 3, TOV1 2.)
 */
#include <avr/io.h>

#include "avrbench_mcu.h"
#include "tmr.h"

AVRBENCH_MCU_SECTION();

volatile uint8_t r[7];
volatile uint8_t done;

#if TMR_MODERN
#define FLAGS TIFR1
#define MASK 0xFF
#else
#define FLAGS TIFR
#define MASK 0x1C
#endif

static void set_all_three(void)
{
    TCCR1B = 0;
    TCNT1 = 0xFF00;
    TCCR1B = _BV(CS10);
    __builtin_avr_delay_cycles(700);
    TCCR1B = 0;
}

int main(void)
{
    OCR1A = 100;
    OCR1B = 200;
    set_all_three();
    r[0] = FLAGS & MASK;
    FLAGS = _BV(OCF1A);
    r[1] = FLAGS & MASK;
    FLAGS |= _BV(TOV1);
    r[2] = FLAGS & MASK;
    FLAGS &= (uint8_t)~_BV(OCF1B);
    r[3] = FLAGS & MASK;
    FLAGS = 0;
    r[4] = FLAGS & MASK;
    set_all_three();
    r[5] = FLAGS & MASK;
    FLAGS = FLAGS;
    r[6] = FLAGS & MASK;
    done = 1;
    for (;;) {
    }
}
