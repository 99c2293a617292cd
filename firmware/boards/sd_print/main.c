// sd_print - prints a G-code file from the SD card of a RAMPS 1.4 with the
// RepRapDiscount Smart Controller (bench/boards/ramps-1.4-smart-controller.yaml,
// scenario tests/scenarios/ramps_sd_print.yaml), the way Marlin's card menu
// does it over the serial line:
//   M20         "Begin file list", "NAME.EXT <size>" per file, "End file list"
//   M23 <name>  "File opened: <name> Size: <n>", "File selected" (or
//               "open failed, File: <name>.")
//   M24         starts the print; "Done printing file" at its end
//   anything else: "ok"
// Each command is answered "ok". The file's lines: G0/G1 with X, Y (mm,
// absolute from where the carriages stood at power-up) and F (mm/min); G90,
// G21 and comments are accepted and ignored. The LCD shows what it does.
// PRINTS_FIRST_FILE: a fault - M23 opens the card's first file, whatever
// its name (the bench must see the moves differ from the selected file's).
//
// The card: SPI mode as the SD Physical Layer Simplified Specification §7.2.1
// brings it up (as firmware/boards/sd_probe); a FAT16 volume from block 0 or
// in the first MBR partition (Microsoft FAT overview §3: BPB, FAT, fixed
// root directory), 8.3 names in the root directory only.
// RAMPS pins (Marlin pins_RAMPS.h): X STEP PF0 DIR PF1 EN PD7, Y STEP PF6
// DIR PF7 EN PF2; 80 steps/mm (ramps-1.4's axes). Display (REPRAP_DISCOUNT_
// SMART_CONTROLLER): LCD RS PH1, E PH0, D4 PA1, D5 PA3, D6 PA5, D7 PA7;
// SDSS PB0, SD_DETECT PL0. Steps are timed on Timer1 running at clk/8.
#include <avr/interrupt.h>
#include <avr/io.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <util/delay.h>
#include <math.h>

#include "avrbench_mcu.h"
#include "fw_line.h"
#include "fw_uart.h"

AVRBENCH_MCU_SECTION();

#define STEPS_PER_MM 80
#define TIMER_HZ 2000000UL  // Timer1 at 16 MHz / 8

volatile uint8_t card_ok;
volatile uint16_t lines_printed;

// --- LCD (HD44780U, 4-bit: "Initializing by Instruction", Figure 24) -----
static void pin(volatile uint8_t* port, uint8_t bit, uint8_t on) {
    if (on) *port |= (uint8_t)(1 << bit);
    else *port &= (uint8_t)~(1 << bit);
}
static void lcd_nibble(uint8_t n) {
    pin(&PORTA, PA1, n & 1);
    pin(&PORTA, PA3, n & 2);
    pin(&PORTA, PA5, n & 4);
    pin(&PORTA, PA7, n & 8);
    PORTH |= (1 << PH0);    // E high >= 230 ns
    _delay_us(1);
    PORTH &= (uint8_t)~(1 << PH0);
    _delay_us(1);
}
static void lcd_send(uint8_t rs, uint8_t value) {
    pin(&PORTH, PH1, rs);
    lcd_nibble(value >> 4);
    lcd_nibble(value & 0x0F);
    _delay_us(50);          // 37 us (Table 6)
}
static void lcd_line(uint8_t row, const char* s) {
    static const uint8_t start[4] = {0x00, 0x40, 0x14, 0x54};  // a 20x4's DDRAM rows
    lcd_send(0, 0x80 | start[row]);
    uint8_t n = 0;
    for (; *s && n < 20; ++n) lcd_send(1, (uint8_t)*s++);
    for (; n < 20; ++n) lcd_send(1, ' ');
}
static void lcd_init(void) {
    DDRH |= (1 << PH1) | (1 << PH0);
    DDRA |= (1 << PA1) | (1 << PA3) | (1 << PA5) | (1 << PA7);
    _delay_ms(50);
    lcd_nibble(0x3);
    _delay_ms(5);
    lcd_nibble(0x3);
    _delay_us(150);
    lcd_nibble(0x3);
    _delay_us(50);
    lcd_nibble(0x2);
    _delay_us(50);
    lcd_send(0, 0x28);
    lcd_send(0, 0x08);
    lcd_send(0, 0x01);
    _delay_ms(2);           // clear: 1.52 ms
    lcd_send(0, 0x06);
    lcd_send(0, 0x0C);
}

// --- SD card in SPI mode ------------------------------------------------------
static uint8_t spi(uint8_t b) {
    SPDR = b;
    while (!(SPSR & (1 << SPIF))) {
    }
    return SPDR;
}
static void card_select(void) { PORTB &= (uint8_t)~(1 << PB0); }
static void card_deselect(void) { PORTB |= (1 << PB0); spi(0xFF); }

static uint8_t card_command(uint8_t index, uint32_t arg, uint8_t crc) {
    spi(0xFF);
    spi(0x40 | index);
    spi((uint8_t)(arg >> 24));
    spi((uint8_t)(arg >> 16));
    spi((uint8_t)(arg >> 8));
    spi((uint8_t)arg);
    spi(crc);
    uint8_t r = 0xFF;
    for (uint8_t i = 0; i < 8 && (r = spi(0xFF)) == 0xFF; ++i) {
    }
    return r;
}

static uint8_t sdhc;
static uint8_t block[512];
static uint32_t block_in_buffer = 0xFFFFFFFFUL;

static uint8_t card_init(void) {
    DDRB |= (1 << PB0) | (1 << PB1) | (1 << PB2);  // SS (the card's CS), SCK, MOSI out
    PORTB |= (1 << PB0);
    PORTL |= (1 << PL0);                           // pull-up on SD_DETECT
    SPCR = (1 << SPE) | (1 << MSTR) | (1 << SPR1) | (1 << SPR0);  // 125 kHz to initialise (<= 400 kHz)
    _delay_us(10);
    if (PINL & (1 << PL0)) return 0;               // no card in the slot
    for (uint8_t i = 0; i < 10; ++i) spi(0xFF);    // >= 74 clocks with CS high
    card_select();
    uint8_t ok = 0;
    if (card_command(0, 0, 0x95) == 0x01) {
        const uint8_t v2 = card_command(8, 0x1AA, 0x87) == 0x01;
        for (uint8_t i = 0; i < 4; ++i) spi(0xFF);
        uint8_t r = 0xFF;
        for (uint16_t tries = 0; tries < 1000 && r != 0; ++tries) {
            card_command(55, 0, 0x01);
            r = card_command(41, v2 ? 0x40000000UL : 0, 0x01);
            _delay_us(500);
        }
        if (r == 0 && card_command(58, 0, 0x01) == 0) {
            sdhc = (spi(0xFF) & 0x40) != 0;
            for (uint8_t i = 0; i < 3; ++i) spi(0xFF);
            ok = 1;
        }
    }
    card_deselect();
    SPCR = (1 << SPE) | (1 << MSTR);               // f/4 = 4 MHz once initialised
    return ok;
}

static uint8_t card_read(uint32_t lba) {
    if (lba == block_in_buffer) return 1;
    card_select();
    uint8_t ok = 0;
    if (card_command(17, sdhc ? lba : lba * 512, 0x01) == 0) {
        uint8_t t = 0xFF;
        for (uint16_t i = 0; i < 10000 && (t = spi(0xFF)) == 0xFF; ++i) {
        }
        if (t == 0xFE) {
            for (uint16_t i = 0; i < 512; ++i) block[i] = spi(0xFF);
            spi(0xFF);  // CRC16, not checked (CMD59 not sent)
            spi(0xFF);
            ok = 1;
        }
    }
    card_deselect();
    block_in_buffer = ok ? lba : 0xFFFFFFFFUL;
    return ok;
}

// --- FAT16 --------------------------------------------------------------------
static uint16_t u16_at(uint16_t i) { return (uint16_t)(block[i] | (uint16_t)block[i + 1] << 8); }
static uint32_t u32_at(uint16_t i) { return u16_at(i) | (uint32_t)u16_at(i + 2) << 16; }

static uint32_t fat_lba, root_lba, data_lba;
static uint16_t root_entries;
static uint8_t sectors_per_cluster;

static uint8_t is_bpb(void) {
    return (block[0] == 0xEB || block[0] == 0xE9) && u16_at(11) == 512 && block[13] != 0;
}

static uint8_t volume_mount(void) {
    if (!card_read(0)) return 0;
    uint32_t base = 0;
    if (!is_bpb()) {
        base = u32_at(446 + 8);                    // the first partition's start
        if (!card_read(base) || !is_bpb()) return 0;
    }
    sectors_per_cluster = block[13];
    const uint16_t reserved = u16_at(14);
    const uint8_t fats = block[16];
    root_entries = u16_at(17);
    const uint16_t fat_sectors = u16_at(22);
    if (fat_sectors == 0) return 0;                // FAT32: not read here
    fat_lba = base + reserved;
    root_lba = fat_lba + (uint32_t)fats * fat_sectors;
    data_lba = root_lba + (root_entries * 32UL + 511) / 512;
    return 1;
}

typedef struct {
    char name[13];
    uint16_t cluster;
    uint32_t size;
} entry_t;

// The root directory's `index`th entry that is a file; 0 past the last.
static uint8_t root_file(uint16_t index, entry_t* e) {
    uint16_t seen = 0;
    for (uint16_t i = 0; i < root_entries; ++i) {
        if (!card_read(root_lba + i / 16)) return 0;
        const uint8_t* d = block + (i % 16) * 32;
        if (d[0] == 0x00) return 0;
        if (d[0] == 0xE5 || (d[11] & 0x0F) == 0x0F || (d[11] & 0x18)) continue;
        if (seen++ != index) continue;
        uint8_t n = 0;
        for (uint8_t k = 0; k < 8 && d[k] != ' '; ++k) e->name[n++] = (char)d[k];
        if (d[8] != ' ') {
            e->name[n++] = '.';
            for (uint8_t k = 8; k < 11 && d[k] != ' '; ++k) e->name[n++] = (char)d[k];
        }
        e->name[n] = 0;
        e->cluster = (uint16_t)(d[26] | d[27] << 8);
        e->size = (uint32_t)d[28] | (uint32_t)d[29] << 8 | (uint32_t)d[30] << 16 | (uint32_t)d[31] << 24;
        return 1;
    }
    return 0;
}

static uint16_t next_cluster(uint16_t cluster) {
    if (!card_read(fat_lba + cluster / 256)) return 0xFFFF;
    return u16_at((uint16_t)((cluster % 256) * 2));
}

// The open file, read a byte at a time.
static entry_t file;
static uint32_t file_pos;
static uint16_t file_cluster;

static int16_t file_getc(void) {
    if (file_pos >= file.size) return -1;
    const uint32_t cluster_bytes = (uint32_t)sectors_per_cluster * 512;
    if (file_pos > 0 && file_pos % cluster_bytes == 0) {
        file_cluster = next_cluster(file_cluster);
        if (file_cluster < 2 || file_cluster >= 0xFFF8) return -1;
    }
    const uint32_t in_cluster = file_pos % cluster_bytes;
    if (!card_read(data_lba + (uint32_t)(file_cluster - 2) * sectors_per_cluster + in_cluster / 512)) return -1;
    ++file_pos;
    return block[in_cluster % 512];
}

// --- motion --------------------------------------------------------------------
static int32_t position_steps[2];
static float feed_mm_per_min = 600;

static void step_pin(uint8_t axis, uint8_t on) {
    if (axis == 0) pin(&PORTF, PF0, on);
    else pin(&PORTF, PF6, on);
}

static void move_to(const int32_t target[2]) {
    int32_t delta[2], count[2] = {0, 0};
    uint32_t n[2];
    for (uint8_t a = 0; a < 2; ++a) {
        delta[a] = target[a] - position_steps[a];
        n[a] = (uint32_t)labs(delta[a]);
    }
    pin(&PORTF, PF1, delta[0] >= 0);               // DIR high = + (ramps-1.4)
    pin(&PORTF, PF7, delta[1] >= 0);
    const uint32_t steps = n[0] > n[1] ? n[0] : n[1];
    if (steps == 0) return;
    const float length_mm = sqrtf((float)n[0] * n[0] + (float)n[1] * n[1]) / STEPS_PER_MM;
    float ticks = length_mm / (feed_mm_per_min / 60.0f) * TIMER_HZ / steps;
    if (ticks < 200) ticks = 200;                  // 10 kHz at most
    if (ticks > 30000) ticks = 30000;
    const uint16_t period = (uint16_t)ticks;
    uint16_t next = TCNT1 + period;                // the DIR setup time passes in the first period
    for (uint32_t s = 1; s <= steps; ++s) {
        while ((int16_t)(TCNT1 - next) < 0) {
        }
        next += period;
        for (uint8_t a = 0; a < 2; ++a) {
            // Bresenham: axis a steps when its share of s passes the next whole step.
            const int32_t due = (int32_t)((uint64_t)n[a] * s / steps);
            if (due > count[a]) {
                count[a] = due;
                step_pin(a, 1);
            }
        }
        _delay_us(2);                              // STEP high >= 1 us (A4988)
        step_pin(0, 0);
        step_pin(1, 0);
    }
    position_steps[0] = target[0];
    position_steps[1] = target[1];
}

static const char* word(const char* s, char letter) {
    for (; *s; ++s) {
        if (*s == letter) return s + 1;
    }
    return 0;
}

static void gcode(const char* s) {
    if (s[0] != 'G') return;
    const int code = atoi(s + 1);
    if (code != 0 && code != 1) return;
    const char* f = word(s, 'F');
    if (f) feed_mm_per_min = (float)atof(f);
    int32_t target[2] = {position_steps[0], position_steps[1]};
    const char* v;
    if ((v = word(s, 'X'))) target[0] = lroundf((float)atof(v) * STEPS_PER_MM);
    if ((v = word(s, 'Y'))) target[1] = lroundf((float)atof(v) * STEPS_PER_MM);
    move_to(target);
}

// --- the card print and the serial commands -------------------------------------
static uint8_t printing;

static void print_file(void) {
    fw_line_t l = {0};
    int16_t c;
    while ((c = file_getc()) >= 0) {
        if (fw_line_feed(&l, (char)c)) {
            gcode(l.text);
            ++lines_printed;
        }
    }
    if (fw_line_feed(&l, '\n')) gcode(l.text);    // a last line without its newline
    printing = 0;
    lcd_line(1, "Done");
    fw_uart_puts("Done printing file\n");
}

static void command(const char* s) {
    if (strncmp(s, "M20", 3) == 0 && (s[3] == 0 || s[3] == ' ')) {
        fw_uart_puts("Begin file list\n");
        entry_t e;
        for (uint16_t i = 0; card_ok && root_file(i, &e); ++i) {
            fw_uart_puts(e.name);
            fw_uart_putc(' ');
            fw_uart_put_u32(e.size);
            fw_uart_putc('\n');
        }
        fw_uart_puts("End file list\n");
    } else if (strncmp(s, "M23 ", 4) == 0) {
        const char* name = s + 4;
        entry_t e;
        uint8_t found = 0;
#ifdef PRINTS_FIRST_FILE
        found = card_ok && root_file(0, &e);  // the bug: whatever name was asked for
#else
        for (uint16_t i = 0; card_ok && !found && root_file(i, &e); ++i) found = strcasecmp(e.name, name) == 0;
#endif
        if (found) {
            file = e;
            file_pos = 0;
            file_cluster = e.cluster;
            fw_uart_puts("File opened: ");
            fw_uart_puts(e.name);
            fw_uart_puts(" Size: ");
            fw_uart_put_u32(e.size);
            fw_uart_puts("\nFile selected\n");
            lcd_line(0, e.name);
        } else {
            fw_uart_puts("open failed, File: ");
            fw_uart_puts(name);
            fw_uart_puts(".\n");
        }
    } else if (strncmp(s, "M24", 3) == 0 && file.name[0]) {
        printing = 1;
    }
    fw_uart_puts("ok\n");
}

int main(void) {
    DDRF |= (1 << PF0) | (1 << PF1) | (1 << PF6) | (1 << PF7) | (1 << PF2);
    DDRD |= (1 << PD7);
    PORTD &= (uint8_t)~(1 << PD7);                 // X and Y drivers enabled (active low)
    PORTF &= (uint8_t)~(1 << PF2);
    TCCR1B = (1 << CS11);                          // Timer1: clk/8, free running
    fw_uart_init(16, 1);                           // 115200 baud
    sei();                                         // the receive interrupt fills fw_uart's ring
    lcd_init();
    lcd_line(0, "sd_print");
    card_ok = card_init() && volume_mount();
    lcd_line(1, card_ok ? "Card ready" : "No card");
    fw_uart_puts("start\n");
    fw_line_t l = {0};
    for (;;) {
        if (printing) {
            lcd_line(1, "Printing");
            print_file();
        }
        const int16_t c = fw_uart_getc();
        if (c < 0) continue;
        if (fw_line_feed(&l, (char)c)) command(l.text);
    }
}
