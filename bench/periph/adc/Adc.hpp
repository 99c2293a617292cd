// Analog inputs of the MCU's ADC as the bench sees them: which port pin is
// which ADC channel, and analog sources sampled when a conversion starts.
//
// simavr's protocol (avr_adc.h): when a conversion starts the ADC raises
// ADC_IRQ_OUT_TRIGGER with the mux descriptor; the outside world answers by
// raising ADC_IRQ_ADCn with the channel's voltage in millivolts. Adc does
// exactly that for every connected channel (both inputs of a differential
// pair), so the voltage is the one at the moment of conversion, and the
// conversion itself (timing, reference, quantisation, ADLAR, ADC8..15 on the
// ATmega2560) is the core's: simavr as corrected by periph/adc/AdcConversion.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/Time.hpp"

struct avr_t;
struct avr_irq_t;

namespace avrbench {

class Adc {
public:
    // Volts at the pin at `cycle` (the start of a conversion).
    using Source = std::function<double(Cycle cycle)>;

    // One input fed to a conversion.
    struct Sample {
        Cycle cycle = 0;            // when the conversion started
        int channel = -1;
        double volts = 0;           // the source's value
        std::uint32_t millivolts = 0;  // what the ADC got (rounded, not negative)
    };

    // Installs on a core whose fixes are in place; inert without an ADC.
    Adc(avr_t* avr, std::string mcu_type);
    ~Adc();
    Adc(const Adc&) = delete;
    Adc& operator=(const Adc&) = delete;

    bool present() const { return irq_base_ != nullptr; }

    // The ADC channel of a port pin ("PK5" on an ATmega2560 is ADC13), from the
    // datasheets' pin tables: ATmega48..328P PC0..PC5 = ADC0..5; ATmega640..2560
    // PF0..7 = ADC0..7, PK0..7 = ADC8..15; ATmega16/32/164..1284 PA0..7 =
    // ADC0..7. Empty for a pin that is no analog input or an MCU not in the table.
    static std::optional<int> channel_for_pin(const std::string& mcu_type, std::string_view pin);
    // Same, for this MCU; throws BadInput naming the MCU's analog pins.
    int channel_for_pin(std::string_view pin) const;
    int channel_count() const { return channel_count_; }

    // Connects a source to a channel (replacing any other). Unconnected
    // channels read their fixed voltage (0 V unless set).
    void connect(int channel, Source source);
    void set_voltage(int channel, double volts);

    // The supply and reference pins in volts (5 V each unless set: the
    // Arduino boards'). REFS selects AVCC, AREF or an internal reference.
    void set_supply(double vcc_volts, double avcc_volts, double aref_volts);

    std::uint64_t samples() const { return samples_; }
    void on_sample(std::function<void(const Sample&)> fn) { listeners_.push_back(std::move(fn)); }

private:
    static void on_trigger(avr_irq_t* irq, std::uint32_t value, void* param);
    void feed(int channel);

    avr_t* avr_;
    std::string mcu_type_;
    avr_irq_t* irq_base_ = nullptr;     // ADC_IRQ_ADC0; ADCn is irq_base_ + n
    avr_irq_t* trigger_irq_ = nullptr;  // ADC_IRQ_OUT_TRIGGER
    int channel_count_ = 0;
    std::vector<Source> sources_;
    std::vector<double> fixed_volts_;
    // Channels given a source or a fixed voltage; the others keep whatever
    // was raised on simavr's ADC_IRQ_ADCn input by someone else.
    std::vector<bool> configured_;
    std::uint64_t samples_ = 0;
    std::vector<std::function<void(const Sample&)>> listeners_;
};

}  // namespace avrbench
