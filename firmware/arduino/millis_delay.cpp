// millis() and delay() as the Arduino core implements them (wiring.c: Timer0
// in fast PWM at clk/64, an overflow every 1024 us, millis() advanced by 1
// with a fractional correction of 24/1000 per overflow).
// D13 (PB5) goes high at setup, low when millis() first reads >= 1000, then
// toggles after each of five delay(100) calls; Serial prints the millis()
// values read at those moments.
#include <Arduino.h>

void setup() {
    Serial.begin(115200);
    pinMode(13, OUTPUT);
    digitalWrite(13, HIGH);
    while (millis() < 1000) {
    }
    digitalWrite(13, LOW);
    Serial.println(millis());
    for (int i = 0; i < 5; ++i) {
        delay(100);
        digitalWrite(13, !digitalRead(13));
    }
    Serial.println(millis());
}

void loop() {}
