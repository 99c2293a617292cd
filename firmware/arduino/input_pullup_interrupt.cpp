// pinMode(INPUT_PULLUP) and attachInterrupt as the Arduino core does them.
// D8 (PB0): INPUT_PULLUP reads HIGH with nothing attached; pinMode(INPUT)
// switches the pull-up off (wiring_digital.c clears PORTB0). D2 (INT0):
// INPUT_PULLUP, attachInterrupt(CHANGE) counts edges the bench drives.
// Serial: "pullup <d8 with pull-up> <d8 without>" then, on any byte received,
// "edges <count>".
#include <Arduino.h>

volatile uint16_t edges;
void on_change() { ++edges; }

void setup() {
    Serial.begin(115200);
    pinMode(8, INPUT_PULLUP);
    const int with_pullup = digitalRead(8);
    pinMode(8, INPUT);
    const int without = digitalRead(8);
    Serial.print("pullup ");
    Serial.print(with_pullup);
    Serial.print(' ');
    Serial.println(without);
    pinMode(2, INPUT_PULLUP);
    attachInterrupt(digitalPinToInterrupt(2), on_change, CHANGE);
}

void loop() {
    if (Serial.available() > 0) {
        Serial.read();
        Serial.print("edges ");
        Serial.println(edges);
    }
}
