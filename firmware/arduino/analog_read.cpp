// analogRead() on every analog input of the board (UNO A0-A5, Mega A0-A15):
// one line on Serial with each result, separated by spaces, then once more
// every 100 ms.
#include <Arduino.h>

#if defined(__AVR_ATmega2560__)
const uint8_t kInputs = 16;
#else
const uint8_t kInputs = 6;
#endif

void setup() { Serial.begin(115200); }

void loop() {
    for (uint8_t i = 0; i < kInputs; ++i) {
        Serial.print(analogRead(A0 + i));
        Serial.print(i + 1 < kInputs ? ' ' : '\n');
    }
    delay(100);
}
