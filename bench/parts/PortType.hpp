// The kind of a part's non-digital port: the interface its provider offers.
// An interface declares its kind (`static constexpr PortType kPort{...}`),
// so the set is open: a new coupling is a new interface header, and the
// board joins ports by comparing kinds, never by knowing them.
#pragma once

#include <string_view>

namespace avrbench {

struct PortType {
    std::string_view name;     // "thermal": what messages call the kind
    std::string_view example;  // "a thermal_plant's body": a provider, for messages
};

// A voltage an MCU's ADC samples: the one kind that shares a net with pins.
inline constexpr PortType kAnalogPort{"analog", "an analog output"};

}  // namespace avrbench
