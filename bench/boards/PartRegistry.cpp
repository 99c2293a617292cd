#include "boards/PartRegistry.hpp"

#include "parts/Axis.hpp"
#include "parts/DeltaRobot.hpp"
#include "parts/Electromagnet.hpp"
#include "parts/Fan.hpp"
#include "parts/Heater.hpp"
#include "parts/LimitSwitch.hpp"
#include "parts/PenLift.hpp"
#include "parts/PullResistor.hpp"
#include "parts/RcServo.hpp"
#include "parts/Relay.hpp"
#include "parts/SerialPeer.hpp"
#include "parts/StepDirDriver.hpp"
#include "parts/ThermalPlant.hpp"
#include "parts/Thermistor.hpp"

namespace avrbench {
namespace {

PartType axis(const std::string& kind) {
    PartType t = simple_part_type<Axis>(kind + "_axis");
    t.implied = {{"kind", kind}};
    return t;
}

}  // namespace

const std::map<std::string, PartType>& part_types() {
    static const std::map<std::string, PartType> types = [] {
        std::map<std::string, PartType> m;
        for (PartType t : {simple_part_type<StepDirDriver>("step_dir_driver"), axis("linear"), axis("rotary"),
                           simple_part_type<LimitSwitch>("limit_switch"), simple_part_type<PullResistor>("pull_resistor"),
                           simple_part_type<SerialPeer>("serial_peer"), simple_part_type<RcServo>("rc_servo"),
                           simple_part_type<ThermalPlant>("thermal_plant"), simple_part_type<Heater>("heater"),
                           simple_part_type<Thermistor>("thermistor"), simple_part_type<Fan>("fan"),
                           simple_part_type<DeltaRobot>("delta_robot"), simple_part_type<Relay>("relay"),
                           simple_part_type<Electromagnet>("electromagnet"), simple_part_type<PenLift>("pen_lift")}) {
            m.emplace(t.name, std::move(t));
        }
        for (PartType t : motor_part_types()) m.emplace(t.name, std::move(t));
        return m;
    }();
    return types;
}

}  // namespace avrbench
