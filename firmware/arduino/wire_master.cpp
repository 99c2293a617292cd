// Wire (Debian's arduino-core-avr library) as master on an UNO: every 20 ms
// it writes "n=<count>" to the slave at address 8, then asks it for 6 bytes
// and prints what came back on Serial at 115200 baud, as the library's
// master_writer and master_reader examples do; five rounds, then "done".
#include <Arduino.h>
#include <Wire.h>

void setup() {
    Wire.begin();  // 100 kHz (TWI_FREQ in utility/twi.h)
    Serial.begin(115200);
    Serial.println("master");
}

void loop() {
    static int round = 0;
    if (round == 5) return;
    delay(20);
    Wire.beginTransmission(8);
    Wire.print("n=");
    Wire.print(round);
    const uint8_t written = Wire.endTransmission();  // 0 = ACKed throughout
    Serial.print("tx ");
    Serial.println(written);
    const uint8_t got = Wire.requestFrom(8, 6);
    Serial.print("rx ");
    Serial.print(got);
    Serial.print(' ');
    while (Wire.available()) Serial.write(static_cast<char>(Wire.read()));
    Serial.println();
    if (++round == 5) Serial.println("done");
}
