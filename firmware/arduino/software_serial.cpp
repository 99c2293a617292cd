// SoftwareSerial (Debian's arduino-core-avr library) at 9600 baud on D10 (RX,
// PB2, pin-change interrupt) and D11 (TX, PB3): prints "ready" and then echoes
// every byte it receives in upper case, as the library's examples do.
#include <Arduino.h>
#include <SoftwareSerial.h>

SoftwareSerial soft(10, 11);  // RX, TX

void setup() {
    soft.begin(9600);
    soft.println("ready");
}

void loop() {
    if (soft.available() > 0) {
        const int c = soft.read();
        soft.write(static_cast<uint8_t>(toupper(c)));
    }
}
