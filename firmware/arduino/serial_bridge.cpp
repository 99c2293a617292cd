// HardwareSerial on two USARTs of a Mega (Debian's arduino-core-avr): what the
// host sends on Serial (USART0) goes out on Serial1 (USART1, TX1 = D18 = PD3)
// and what comes in on Serial1 (RX1 = D19 = PD2) goes back to the host, the
// serial pass-through sketches of the Arduino examples do. Prints "bridge"
// first. At 9600 baud on Serial1, so a SoftwareSerial sketch can sit on the
// other end of the two wires.
#include <Arduino.h>

void setup() {
    Serial.begin(115200);
    Serial1.begin(9600);
    Serial.println("bridge");
}

void loop() {
    if (Serial.available() > 0) Serial1.write(static_cast<uint8_t>(Serial.read()));
    if (Serial1.available() > 0) Serial.write(static_cast<uint8_t>(Serial1.read()));
}
