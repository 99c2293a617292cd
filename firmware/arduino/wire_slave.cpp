// Wire (Debian's arduino-core-avr library) as slave at address 8: prints
// what each master write carried on Serial at 115200 baud (slave_receiver
// example) and answers a read with the 6 bytes "ok#<k>..", k counting the
// writes it has seen (slave_sender example).
#include <Arduino.h>
#include <Wire.h>

static volatile uint8_t writes_seen = 0;

void on_receive(int count) {
    Serial.print("got ");
    Serial.print(count);
    Serial.print(' ');
    while (Wire.available()) Serial.write(static_cast<char>(Wire.read()));
    Serial.println();
    ++writes_seen;
}

void on_request() {
    char reply[] = "ok#0..";
    reply[3] = static_cast<char>('0' + writes_seen % 10);
    Wire.write(reply, 6);
}

void setup() {
    Wire.begin(8);
    Wire.onReceive(on_receive);
    Wire.onRequest(on_request);
    Serial.begin(115200);
    Serial.println("slave");
}

void loop() {}
