// What a thermal plant offers the parts coupled to it: heaters add power to
// a node, fans cool it, a thermistor reads its sensor node.
#pragma once

#include <string>

#include "core/Time.hpp"
#include "parts/PortType.hpp"

namespace avrbench {

class ThermalBody {
public:
    static constexpr PortType kPort{"thermal", "a thermal_plant's body"};
    virtual ~ThermalBody() = default;
    // A heater of at most `max_power_W` on `node` ("block" or "surface");
    // BadInput when the body cannot take it. Returns the source's handle.
    virtual int add_heat_source(const std::string& node, double max_power_W) = 0;
    virtual void set_heat_source_power(int source, double watts) = 0;
    virtual double fan_speed() const = 0;             // 0..1 of full speed
    virtual void set_fan_speed(double fraction) = 0;  // 0..1 of full speed
    // The temperature at the sensor node now (degC).
    virtual double sensor_degC() = 0;
    // A sensor fallen out of its bore follows ambient instead.
    virtual void set_sensor_detached(bool detached) = 0;
    // A thermistor sits on this body (it calls this once, when connected),
    // and the firmware read it now (an ADC conversion started on its
    // divider): heating with no sensor read is a finding of the body's.
    virtual void attach_sensor() = 0;
    virtual void sensor_read(Cycle cycle) = 0;
};

}  // namespace avrbench
