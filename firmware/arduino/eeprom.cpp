// The EEPROM library: write 16 bytes (address a holds 3 * a + 7), read them
// back through EEPROM.read and EEPROM.get, print their sum: the sum of
// 3a + 7 for a = 0..15 is 3 * 120 + 16 * 7 = 472, for each read path.
#include <Arduino.h>
#include <EEPROM.h>

void setup() {
    Serial.begin(115200);
    for (int a = 0; a < 16; ++a) EEPROM.write(a, static_cast<uint8_t>(3 * a + 7));
    unsigned sum = 0;
    for (int a = 0; a < 16; ++a) sum += EEPROM.read(a);
    uint8_t block[16];
    EEPROM.get(0, block);
    unsigned sum_get = 0;
    for (uint8_t b : block) sum_get += b;
    Serial.print("eeprom ");
    Serial.print(sum);
    Serial.print(' ');
    Serial.println(sum_get);
}

void loop() {}
