// A line protocol on SoftwareSerial (Debian's arduino-core-avr library), 9600
// baud on D10 (RX, PB2) and D11 (TX, PB3): prints "start", then reads each
// line whole and answers "echo:" with the line in upper case, then "ok" - a
// G-code firmware's answer on a port with no USART behind it. The library
// transmits with interrupts off and cannot receive meanwhile (its documented
// half-duplex limit), so lines end in '\n' alone: after println's '\r' a host
// that takes it as the line's end (the bench's does) would start sending
// while the '\n' still goes out, and the sketch would miss the start bits.
#include <Arduino.h>
#include <SoftwareSerial.h>

SoftwareSerial soft(10, 11);  // RX, TX
char line[64];
unsigned length = 0;

void setup() {
    soft.begin(9600);
    soft.print("start\n");
}

void loop() {
    if (soft.available() == 0) return;
    const int c = soft.read();
    if (c == '\r') return;
    if (c != '\n') {
        if (length < sizeof line - 1) line[length++] = static_cast<char>(toupper(c));
        return;
    }
    line[length] = '\0';
    soft.print("echo:");
    soft.print(line);
    soft.print("\nok\n");
    length = 0;
}
