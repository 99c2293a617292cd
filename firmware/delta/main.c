/*
 * delta - seed 004's delta robot controller (Vagenas 2014) on an Arduino
 * Mega 2560 at 16 MHz (bench/boards/delta-seed004.yaml).
 *
 * Three RC servos on D9 (PH6), D10 (PB4), D11 (PB5), pulsed one after the
 * other in 20 ms frames by Timer1 (CTC at clk/8: 0.5 us ticks), as the Servo
 * library the thesis used does on its timer: S1, then S2, then S3, never
 * overlapping; a new width takes effect at the next frame. The electromagnet
 * relay is on D12 (PB6), the warning LED relay on D8 (PH5). Timer0 ticks
 * milliseconds for delay(). Serial: USART0, 9600 baud (UBRR0 = 207, U2X, as
 * the Arduino core), transmit through a ring like Serial's.
 *
 * The thesis' program, as its loop() runs it: LED on, all servos at their
 * "horizontal" table entries (servoN[offset_N]), 2 s, then the 74 rows of
 * positionMatrix (x, y, z in cm, dwell in ms, magnet): inverse kinematics,
 * the three rounded angles printed one per line and a blank line, the
 * servos to servoN[offset_N - angle_N], the magnet relay, the dwell; LED
 * off, servos horizontal, 10 s; again.
 *
 * The thesis' defects (digest §4) and what this build does instead:
 *  - delta_calcInverse returned nothing and every status was ignored: here
 *    it returns the first failure, and a target is used only if all three
 *    arms reach it;
 *  - delta_calcAngleYZ rejected theta < 0, i.e. every arm above the base
 *    plane, though the program's own targets need -40..57 deg: here an
 *    angle is valid when its table index offset - angle lies in 0..180 (the
 *    servo's calibrated range);
 *  - the call was spelled delta_calInverse (did not compile);
 *  - nothing kept the target below the base: z = 0 made every angle NaN
 *    and the move was carried out with whatever (int)round(NaN) gave (found
 *    by fuzzing this build, `G1 Z0`); here z must be below 0.
 * THESIS_LITERAL builds the listing's behaviour: angles used whatever the
 * status, and table indexes unchecked (an index outside 0..180 reads past
 * the table).
 *
 * Commands (9600 baud, one per line, any byte stops the program after the
 * current row): "G1 X<mm> Y<mm> Z<mm>" moves the effector there (modal:
 * missing words keep the last target; F taken and ignored) -> "ok", or
 * "error: unreachable" when an arm cannot reach it or its servo index leaves
 * the table, "error: bad word" for any other word or number form; "M3" / "M5"
 * switch the magnet on / off -> "ok"; anything else -> "error: unknown
 * command". A line longer than 47 characters -> "error: line too long".
 * A G1's "ok" comes once the servos have had time to get there: the largest
 * angle change at the SM-S4315M's 0.21 s / 60 deg (285 deg/s), plus two
 * 20 ms frames (the new width starts with the next frame). Answering at
 * once would let the next command turn the servos before they arrive: the
 * effector cuts the corner and never reaches the target it was told
 * (the motion oracle reports it, docs/DELTA.md). The thesis' program has
 * its dwells instead; both builds wait alike, this is our command loop.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "avrbench_mcu.h"
#include "fw_line.h"
#include "fw_uart.h"

AVRBENCH_MCU_SECTION();

/* --- geometry (seed 004 §1, the firmware's cm) ----------------------------- */
static const float e = 8.0;
static const float f = 23.32;
static const float re = 35.0;
static const float rf = 6.0;
static const float pi = 3.141592653;
#define SIN120 0.8660254f
#define COS120 (-0.5f)

/* --- Table 4.1: pulse width (us) for 0..180 servo degrees, per servo -------- */
static int servo1[181] = {
    641, 651, 659, 668, 676, 680, 690, 700, 706, 714, 722, 730, 737, 746, 754,
    763, 772, 779, 788, 796, 808, 815, 825, 833, 843, 854, 862, 871, 878, 888,
    896, 903, 910, 919, 932, 943, 951, 960, 969, 976, 986, 996, 1007, 1016, 1022,
    1032, 1043, 1050, 1060, 1071, 1081, 1089, 1097, 1108, 1116, 1127, 1137, 1147, 1158, 1169,
    1180, 1189, 1198, 1206, 1216, 1226, 1236, 1248, 1258, 1268, 1274, 1285, 1300, 1307, 1317,
    1328, 1338, 1348, 1357, 1364, 1374, 1386, 1395, 1406, 1413, 1421, 1432, 1443, 1454, 1463,
    1474, 1483, 1492, 1498, 1508, 1520, 1529, 1538, 1547, 1557, 1566, 1578, 1586, 1596, 1607,
    1615, 1625, 1631, 1639, 1655, 1664, 1675, 1683, 1694, 1703, 1711, 1726, 1737, 1746, 1756,
    1765, 1770, 1780, 1791, 1801, 1812, 1821, 1830, 1839, 1851, 1861, 1867, 1877, 1887, 1894,
    1902, 1911, 1924, 1933, 1940, 1948, 1956, 1968, 1977, 1985, 1994, 2004, 2011, 2023, 2030,
    2040, 2049, 2057, 2065, 2075, 2084, 2093, 2103, 2109, 2119, 2129, 2137, 2146, 2153, 2161,
    2170, 2180, 2188, 2199, 2208, 2220, 2228, 2234, 2242, 2252, 2264, 2271, 2279, 2288, 2296,
    2305
};
static int servo2[181] = {
    587, 594, 600, 608, 612, 620, 627, 633, 641, 651, 659, 662, 672, 680, 688,
    695, 703, 713, 721, 730, 738, 744, 752, 761, 768, 777, 783, 791, 802, 809,
    819, 827, 835, 847, 856, 861, 873, 883, 889, 896, 907, 916, 925, 935, 941,
    953, 961, 970, 976, 984, 995, 1003, 1012, 1024, 1033, 1043, 1050, 1059, 1069, 1077,
    1086, 1100, 1105, 1117, 1128, 1136, 1146, 1156, 1165, 1178, 1185, 1194, 1206, 1213, 1225,
    1232, 1241, 1251, 1261, 1268, 1275, 1288, 1298, 1307, 1321, 1330, 1335, 1348, 1356, 1369,
    1373, 1384, 1396, 1408, 1418, 1426, 1437, 1449, 1460, 1469, 1476, 1488, 1498, 1507, 1520,
    1531, 1540, 1549, 1560, 1572, 1583, 1593, 1601, 1614, 1623, 1637, 1645, 1656, 1672, 1682,
    1691, 1700, 1710, 1717, 1729, 1743, 1754, 1764, 1776, 1789, 1800, 1812, 1818, 1829, 1841,
    1851, 1862, 1869, 1882, 1888, 1898, 1911, 1920, 1931, 1943, 1954, 1961, 1970, 1976, 1988,
    2000, 2008, 2016, 2029, 2038, 2047, 2056, 2064, 2080, 2090, 2099, 2109, 2120, 2132, 2139,
    2147, 2159, 2170, 2178, 2187, 2198, 2205, 2215, 2228, 2239, 2249, 2256, 2265, 2276, 2282,
    2296
};
static int servo3[181] = {
    587, 596, 603, 609, 616, 626, 632, 640, 648, 657, 665, 671, 679, 688, 696,
    701, 708, 716, 722, 729, 739, 749, 755, 764, 771, 780, 787, 794, 806, 814,
    820, 827, 834, 843, 852, 861, 870, 878, 888, 896, 904, 911, 923, 931, 941,
    952, 959, 968, 980, 987, 995, 1003, 1014, 1023, 1034, 1042, 1052, 1060, 1071, 1080,
    1088, 1096, 1108, 1118, 1128, 1138, 1146, 1158, 1167, 1175, 1185, 1196, 1206, 1215, 1224,
    1235, 1243, 1254, 1263, 1272, 1284, 1294, 1303, 1315, 1325, 1333, 1346, 1356, 1365, 1376,
    1386, 1395, 1402, 1413, 1423, 1432, 1440, 1451, 1460, 1469, 1477, 1486, 1496, 1508, 1518,
    1524, 1534, 1544, 1554, 1563, 1573, 1584, 1596, 1603, 1610, 1621, 1630, 1637, 1652, 1661,
    1670, 1680, 1688, 1698, 1706, 1719, 1728, 1738, 1746, 1757, 1769, 1779, 1788, 1793, 1802,
    1813, 1821, 1830, 1843, 1852, 1862, 1874, 1882, 1893, 1902, 1912, 1920, 1931, 1938, 1946,
    1957, 1964, 1972, 1981, 1991, 1998, 2010, 2017, 2027, 2036, 2042, 2053, 2060, 2070, 2079,
    2086, 2095, 2102, 2111, 2119, 2128, 2137, 2146, 2153, 2162, 2169, 2175, 2184, 2193, 2202,
    2208
};

static const int offset[3] = {111, 110, 116}; /* servo degrees with the upper arms horizontal */

/* --- servo pulses (Timer1) ---------------------------------------------------- */
#define FRAME_TICKS 40000u /* 20 ms in 0.5 us ticks */
static volatile uint16_t servo_us[3];
static uint16_t frame_ticks[3];
static uint8_t phase = 3; /* the period now starting: 0..2 servo n's pulse, 3 the rest of the frame */
static uint8_t next_h = _BV(PH6), next_b; /* the servo pins' levels at the next compare: S1 rises first */
volatile uint32_t frames;

/* The pins change first thing in the interrupt, always with the same two
 * writes, so every edge lags its compare match by the same few cycles and
 * the pulse widths are exactly the OCR1A periods (0.5 us each). */
ISR(TIMER1_COMPA_vect)
{
    PORTH = (uint8_t)((PORTH & (uint8_t)~_BV(PH6)) | next_h);
    PORTB = (uint8_t)((PORTB & (uint8_t)~(_BV(PB4) | _BV(PB5))) | next_b);
    phase = phase == 3 ? 0 : (uint8_t)(phase + 1);
    switch (phase) {
        case 0: /* S1 rose */
            for (uint8_t n = 0; n < 3; ++n) frame_ticks[n] = (uint16_t)(servo_us[n] * 2u);
            OCR1A = frame_ticks[0] - 1;
            next_h = 0;
            next_b = _BV(PB4);
            ++frames;
            break;
        case 1: /* S1 fell, S2 rose */
            OCR1A = frame_ticks[1] - 1;
            next_b = _BV(PB5);
            break;
        case 2: /* S2 fell, S3 rose */
            OCR1A = frame_ticks[2] - 1;
            next_b = 0;
            break;
        default: /* S3 fell: the rest of the 20 ms */
            OCR1A = (uint16_t)(FRAME_TICKS - frame_ticks[0] - frame_ticks[1] - frame_ticks[2] - 1u);
            next_h = _BV(PH6);
            break;
    }
}

static void servos_start(void)
{
    DDRH |= _BV(PH6);
    DDRB |= _BV(PB4) | _BV(PB5);
    TCCR1A = 0;
    OCR1A = 100;
    TIMSK1 = _BV(OCIE1A);
    TCCR1B = _BV(WGM12) | _BV(CS11); /* CTC, clk/8 */
}

static void servo_write_us(uint8_t n, int us)
{
    cli();
    servo_us[n] = (uint16_t)us;
    sei();
}

/* --- milliseconds (Timer0) ------------------------------------------------------ */
static volatile uint32_t ms;

ISR(TIMER0_COMPA_vect) { ++ms; }

static uint32_t millis(void)
{
    cli();
    const uint32_t now = ms;
    sei();
    return now;
}

/* --- commands ---------------------------------------------------------------------- */
static fw_line_t line;
static uint8_t command_mode;

/* Waits `n` ms, sleeping between interrupts; returns early when a byte arrives. */
static void delay_ms(uint32_t n)
{
    const uint32_t start = millis();
    while (millis() - start < n) {
        if (command_mode) return;
        fw_uart_idle();
        int16_t c;
        while ((c = fw_uart_getc()) >= 0) {
            command_mode = 1;
            if (fw_line_feed(&line, (char)c)) return; /* handled by the command loop */
        }
    }
}

/* --- kinematics (seed 004 §2, the thesis' formulas in cm) ---------------------- */
static int8_t calc_angle_yz(float x0, float y0, float z0, float *theta)
{
    float y1 = -0.5 * 0.57735 * f;
    y0 -= 0.5 * 0.57735 * e;
    float a = (x0 * x0 + y0 * y0 + z0 * z0 + rf * rf - re * re - y1 * y1) / (2 * z0);
    float b = (y1 - y0) / z0;
    float d = -(a + b * y1) * (a + b * y1) + rf * (b * b * rf + rf);
    if (d < 0) return -1;
    float yj = (y1 - a * b - sqrt(d)) / (b * b + 1);
    float zj = a + b * yj;
    *theta = 180.0 * atan(-zj / (y1 - yj)) / pi + ((yj > y1) ? 180.0 : 0.0);
#ifdef THESIS_LITERAL
    if ((*theta < 0) || (*theta > 180)) return -1;
#endif
    return 0;
}

static int8_t calc_inverse(float x0, float y0, float z0, float theta[3])
{
    theta[0] = theta[1] = theta[2] = 0;
    int8_t status = calc_angle_yz(x0, y0, z0, &theta[0]);
    const int8_t s2 = calc_angle_yz(x0 * COS120 + y0 * SIN120, y0 * COS120 - x0 * SIN120, z0, &theta[1]);
    const int8_t s3 = calc_angle_yz(x0 * COS120 - y0 * SIN120, y0 * COS120 + x0 * SIN120, z0, &theta[2]);
    if (status == 0) status = s2;
    if (status == 0) status = s3;
    return status;
}

/* Rounds the angles and finds the table entries; 0 when every arm can go there. */
static int8_t plan(float x_cm, float y_cm, float z_cm, int angle[3])
{
    float theta[3];
    const int8_t status = calc_inverse(x_cm, y_cm, z_cm, theta);
    /* The robot hangs below its base: z = 0 divides by zero in
     * calc_angle_yz (NaN passes "d < 0"), z > 0 is through the base plate. */
    int8_t ok = status == 0 && z_cm < 0;
    for (uint8_t n = 0; n < 3; ++n) {
        if (!isfinite(theta[n])) {
            ok = 0;
            theta[n] = 0;
        }
        angle[n] = (int)round(theta[n]);
        const int index = offset[n] - angle[n];
        if (index < 0 || index > 180) ok = 0;
    }
#ifdef THESIS_LITERAL
    (void)ok;
    return 0; /* the listing used the angles whatever the status */
#else
    return ok ? 0 : -1;
#endif
}

/* The arm angles last written (0: horizontal), for the time the servos need. */
static int written_angle[3];

static void move_servos(const int angle[3])
{
    servo_write_us(0, servo1[offset[0] - angle[0]]);
    servo_write_us(1, servo2[offset[1] - angle[1]]);
    servo_write_us(2, servo3[offset[2] - angle[2]]);
    for (uint8_t n = 0; n < 3; ++n) written_angle[n] = angle[n];
}

static void servos_horizontal(void)
{
    servo_write_us(0, servo1[offset[0]]);
    servo_write_us(1, servo2[offset[1]]);
    servo_write_us(2, servo3[offset[2]]);
    for (uint8_t n = 0; n < 3; ++n) written_angle[n] = 0;
}

/* How long the servos take from the angles last written to `angle`, in ms:
 * 285 deg/s (SM-S4315M: 0.21 s / 60 deg) plus two 20 ms frames; a change
 * beyond a servo's 180 deg of travel (the literal build's unchecked index)
 * counts as 180. */
static uint16_t servo_travel_ms(const int angle[3])
{
    int largest = 0;
    for (uint8_t n = 0; n < 3; ++n) {
        const long change = labs((long)angle[n] - written_angle[n]);
        const int deg = change > 180 ? 180 : (int)change;
        if (deg > largest) largest = deg;
    }
    return (uint16_t)(((uint32_t)largest * 1000 + 284) / 285 + 40);
}

/* Waits `n` ms asleep between interrupts; bytes wait in the receive ring. */
static void settle_ms(uint16_t n)
{
    const uint32_t start = millis();
    while (millis() - start < n) fw_uart_idle();
}

static void magnet(uint8_t on)
{
    if (on) PORTB |= _BV(PB6);
    else PORTB &= (uint8_t)~_BV(PB6);
}

static void led(uint8_t on)
{
    /* PORTH is beyond SBI/CBI's reach: a read-modify-write the servo
     * interrupt (which writes PH6) must not split. */
    cli();
    if (on) PORTH |= _BV(PH5);
    else PORTH &= (uint8_t)~_BV(PH5);
    sei();
}

/* --- the thesis' program (seed 004 §4: x, y, z cm, dwell ms, magnet) ------------ */
static const float position_matrix[74][5] = {
    {0, 0, -31.0, 1000, 0},
    {-3.3, -6.7, -31.0, 1000, 0},
    {-3.3, -6.7, -34.0, 1000, 0},
    {-3.3, -6.7, -34.0, 1000, 1},
    {-3.3, -6.7, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {-3.3, 0, -31.0, 1000, 0},
    {-3.3, 0, -34.0, 1000, 0},
    {-3.3, 0, -34.0, 1000, 1},
    {-3.3, 0, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {-3.3, 6.7, -31.0, 1000, 0},
    {-3.3, 6.7, -34.0, 1000, 0},
    {-3.3, 6.7, -34.0, 1000, 1},
    {-3.3, 6.7, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {3.3, -6.7, -31.0, 1000, 0},
    {3.3, -6.7, -34.0, 1000, 0},
    {3.3, -6.7, -34.0, 1000, 1},
    {3.3, -6.7, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {3.3, 0, -31.0, 1000, 0},
    {3.3, 0, -34.0, 1000, 0},
    {3.3, 0, -34.0, 1000, 1},
    {3.3, 0, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {3.3, 6.7, -31.0, 1000, 0},
    {3.3, 6.7, -34.0, 1000, 0},
    {3.3, 6.7, -34.0, 1000, 1},
    {3.3, 6.7, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {10.0, -6.7, -31.0, 1000, 0},
    {10.0, -6.7, -34.0, 1000, 0},
    {10.0, -6.7, -34.0, 1000, 1},
    {10.0, -6.7, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {10.0, 0, -31.0, 1000, 0},
    {10.0, 0, -34.0, 1000, 0},
    {10.0, 0, -34.0, 1000, 1},
    {10.0, 0, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31.0, 1000, 0},
    {10.0, 6.7, -31.0, 1000, 0},
    {10.0, 6.7, -34.0, 1000, 0},
    {10.0, 6.7, -34.0, 1000, 1},
    {10.0, 6.7, -31.0, 1000, 1},
    {-10, 0, -31.0, 1000, 1},
    {-10, 0, -32.0, 1000, 1},
    {-10, 0, -32.0, 1000, 0},
    {-10, 0, -31, 1000, 0},
    {0, 0, -31, 1000, 0}
};

static void println_int(int v)
{
    fw_uart_put_i32(v);
    fw_uart_puts("\r\n");
}

static void run_program(void)
{
    led(1);
    servos_horizontal();
    delay_ms(2000);
    for (uint8_t i = 0; i < 74 && !command_mode; ++i) {
        int angle[3];
        const int8_t reachable = plan(position_matrix[i][0], position_matrix[i][1], position_matrix[i][2], angle) == 0;
        for (uint8_t n = 0; n < 3; ++n) println_int(angle[n]);
        fw_uart_puts("\r\n");
        if (reachable) move_servos(angle); /* (every row of the thesis' program is) */
        magnet(position_matrix[i][4] != 0);
        delay_ms((uint32_t)position_matrix[i][3]);
    }
    if (command_mode) return;
    led(0);
    servos_horizontal();
    delay_ms(10000);
}

/* "G1 X.. Y.. Z.." in mm (modal), "M3", "M5". */
static float target_mm[3] = {0, 0, -310};

/* The words of a G0/G1 line after its code: X, Y, Z (mm) and F (taken and
 * ignored: the servos run at their own speed), each at most once, each a
 * plain decimal number ([+-]digits[.digits]), spaces between. 0 for
 * anything else: an exponent, another letter (G20, a second G), a word
 * twice - lines a G-code reader would take differently from atof (fuzzing
 * found "G1 Z-34G20": Z -34 mm here, -863.6 mm to a reader that honours
 * G20). */
static int8_t read_move_words(const char *p, float next[3])
{
    uint8_t seen = 0;
    for (;;) {
        while (*p == ' ') ++p;
        if (*p == '\0') return 1;
        const char letter = *p++;
        const uint8_t axis = letter == 'X' ? 0 : letter == 'Y' ? 1 : letter == 'Z' ? 2 : letter == 'F' ? 3 : 4;
        if (axis == 4 || (seen & (1u << axis))) return 0;
        seen |= (uint8_t)(1u << axis);
        const char *number = p;
        if (*p == '+' || *p == '-') ++p;
        uint8_t digits = 0;
        for (; *p >= '0' && *p <= '9'; ++p) ++digits;
        if (*p == '.') {
            for (++p; *p >= '0' && *p <= '9'; ++p) ++digits;
        }
        if (digits == 0) return 0;
        if (axis < 3) next[axis] = (float)atof(number);
    }
}

static void execute(const char *text)
{
    while (*text == ' ') ++text;
    if (text[0] == 'G' && (text[1] == '0' || text[1] == '1') && (text[2] == ' ' || text[2] == '\0')) {
        float next[3] = {target_mm[0], target_mm[1], target_mm[2]};
        if (!read_move_words(text + 2, next)) {
            fw_uart_puts("error: bad word\r\n");
            return;
        }
        int angle[3];
        if (plan(next[0] / 10, next[1] / 10, next[2] / 10, angle) != 0) {
            fw_uart_puts("error: unreachable\r\n");
            return;
        }
        for (uint8_t n = 0; n < 3; ++n) target_mm[n] = next[n];
        const uint16_t travel_ms = servo_travel_ms(angle);
        move_servos(angle);
        settle_ms(travel_ms);
        fw_uart_puts("ok\r\n");
    } else if (text[0] == 'M' && (text[1] == '3' || text[1] == '5') && text[2] == '\0') {
        magnet(text[1] == '3');
        fw_uart_puts("ok\r\n");
    } else {
        fw_uart_puts("error: unknown command\r\n");
    }
}

int main(void)
{
    DDRB |= _BV(PB6) | _BV(PB7); /* magnet relay; D13 as the listing sets it */
    DDRH |= _BV(PH5);            /* LED relay */
    fw_uart_init(207, 1);
    TCCR0A = _BV(WGM01); /* CTC: 16 MHz / 64 / 250 = 1 kHz */
    OCR0A = 249;
    TIMSK0 = _BV(OCIE0A);
    TCCR0B = _BV(CS01) | _BV(CS00);
    servos_horizontal();
    servos_start();
    sei();
    while (!command_mode) run_program();
    for (;;) {
        if (line.complete) {
            if (line.overflow) fw_uart_puts("error: line too long\r\n");
            else execute(line.text);
            line.complete = 0;
            line.length = 0;
            line.overflow = 0;
        }
        const int16_t c = fw_uart_getc();
        if (c < 0) fw_uart_idle();
        else (void)fw_line_feed(&line, (char)c);
    }
}
