#include "periph/adc/Adc.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

extern "C" {
#include <avr_adc.h>
#include <sim_avr.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "core/Errors.hpp"
#include "periph/Fix.hpp"

namespace avrbench {
namespace {

struct AnalogPort {
    char port;
    int first_channel;  // channel of bit 0
    int pins;           // bits 0 .. pins-1 are analog inputs
};

// From the datasheets' pin descriptions ("Port X ... serves as analog inputs").
std::vector<AnalogPort> analog_ports(const std::string& mcu_type) {
    static const std::vector<std::string> k328 = {"atmega48", "atmega48p", "atmega88", "atmega88p", "atmega168",
                                                  "atmega168p", "atmega328", "atmega328p", "atmega8"};
    static const std::vector<std::string> k2560 = {"atmega640", "atmega1280", "atmega2560"};
    static const std::vector<std::string> k32 = {"atmega16",  "atmega32",   "atmega164", "atmega164p", "atmega324",
                                                 "atmega324p", "atmega324a", "atmega644", "atmega644p", "atmega1284",
                                                 "atmega1284p"};
    auto in = [&](const std::vector<std::string>& list) {
        return std::find(list.begin(), list.end(), mcu_type) != list.end();
    };
    // ATmega328P §1.1.3/§1.1.4: PC0..PC5 are ADC0..5 (ADC6/7 of the TQFP have no port pin).
    if (in(k328)) return {{'C', 0, 6}};
    // ATmega2560 §1.1: Port F = ADC0..7, Port K = ADC8..15.
    if (in(k2560)) return {{'F', 0, 8}, {'K', 8, 8}};
    // ATmega32 §2.2 "Port A (PA7..PA0): analog inputs to the A/D Converter".
    if (in(k32)) return {{'A', 0, 8}};
    return {};
}

int channels_of(const std::string& mcu_type) {
    int n = 0;
    for (const auto& p : analog_ports(mcu_type)) n = std::max(n, p.first_channel + p.pins);
    return n;
}

std::string analog_pin_list(const std::string& mcu_type) {
    std::string out;
    for (const auto& p : analog_ports(mcu_type)) {
        if (!out.empty()) out += ", ";
        out += std::string("P") + p.port + "0..P" + p.port + static_cast<char>('0' + p.pins - 1) + " = ADC" +
               std::to_string(p.first_channel) + ".." + std::to_string(p.first_channel + p.pins - 1);
    }
    return out;
}

}  // namespace

std::optional<int> Adc::channel_for_pin(const std::string& mcu_type, std::string_view pin) {
    std::string_view s = pin;
    if (s.size() == 3 && (s[0] == 'P' || s[0] == 'p')) s.remove_prefix(1);
    if (s.size() != 2 || s[1] < '0' || s[1] > '7') return std::nullopt;
    const char port = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
    const int bit = s[1] - '0';
    for (const auto& p : analog_ports(mcu_type)) {
        if (p.port == port && bit < p.pins) return p.first_channel + bit;
    }
    return std::nullopt;
}

int Adc::channel_for_pin(std::string_view pin) const {
    auto channel = channel_for_pin(mcu_type_, pin);
    if (!channel) {
        const std::string list = analog_pin_list(mcu_type_);
        throw BadInput(mcu_type_ + " pin '" + std::string(pin) + "' is not an ADC input" +
                       (list.empty() ? std::string(" (the bench knows no analog pins of this MCU)") : " (" + list + ")"));
    }
    if (!present()) throw BadInput(mcu_type_ + " has no ADC in simavr");
    return *channel;
}

Adc::Adc(avr_t* avr, std::string mcu_type) : avr_(avr), mcu_type_(std::move(mcu_type)) {
    if (find_io_module(avr_, "adc") == nullptr) return;
    // The core's ADC fix gives the module an IRQ array with all 16 inputs
    // (simavr's own keeps ADC0..7); getirq returns whichever is installed.
    irq_base_ = avr_io_getirq(avr_, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0);
    trigger_irq_ = avr_io_getirq(avr_, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER);
    if (irq_base_ == nullptr || trigger_irq_ == nullptr) {
        irq_base_ = nullptr;
        return;
    }
    channel_count_ = std::max(channels_of(mcu_type_), 8);
    sources_.resize(static_cast<std::size_t>(channel_count_));
    fixed_volts_.assign(static_cast<std::size_t>(channel_count_), 0.0);
    configured_.assign(static_cast<std::size_t>(channel_count_), false);
    avr_irq_register_notify(trigger_irq_, &Adc::on_trigger, this);
    // The core assumes 5 V supplies when none are set; say so explicitly.
    if (avr_->vcc == 0 || avr_->avcc == 0 || avr_->aref == 0) set_supply(5.0, 5.0, 5.0);
}

Adc::~Adc() {
    if (trigger_irq_ != nullptr) avr_irq_unregister_notify(trigger_irq_, &Adc::on_trigger, this);
}

void Adc::connect(int channel, Source source) {
    if (channel < 0 || channel >= channel_count_) {
        throw BadInput(mcu_type_ + " has no ADC channel " + std::to_string(channel));
    }
    sources_[static_cast<std::size_t>(channel)] = std::move(source);
    configured_[static_cast<std::size_t>(channel)] = true;
}

void Adc::set_voltage(int channel, double volts) {
    if (channel < 0 || channel >= channel_count_) {
        throw BadInput(mcu_type_ + " has no ADC channel " + std::to_string(channel));
    }
    sources_[static_cast<std::size_t>(channel)] = nullptr;
    fixed_volts_[static_cast<std::size_t>(channel)] = volts;
    configured_[static_cast<std::size_t>(channel)] = true;
}

void Adc::set_supply(double vcc_volts, double avcc_volts, double aref_volts) {
    // simavr keeps these in millivolts (sim_avr.h); the conversion reads them.
    avr_->vcc = static_cast<std::uint32_t>(std::lround(vcc_volts * 1000));
    avr_->avcc = static_cast<std::uint32_t>(std::lround(avcc_volts * 1000));
    avr_->aref = static_cast<std::uint32_t>(std::lround(aref_volts * 1000));
}

void Adc::on_trigger(avr_irq_t*, std::uint32_t value, void* param) {
    auto* self = static_cast<Adc*>(param);
    // The descriptor of the conversion that starts (avr_adc.c packs it so).
    union {
        avr_adc_mux_t mux;
        std::uint32_t v;
    } e;
    e.v = value;
    const avr_adc_mux_t mux = e.mux;
    if (mux.kind == ADC_MUX_SINGLE) {
        self->feed(static_cast<int>(mux.src));
    } else if (mux.kind == ADC_MUX_DIFF) {
        self->feed(static_cast<int>(mux.src));
        self->feed(static_cast<int>(mux.diff));
    }
}

void Adc::feed(int channel) {
    if (channel < 0 || channel >= channel_count_ || !configured_[static_cast<std::size_t>(channel)]) return;
    Sample s;
    s.cycle = avr_->cycle;
    s.channel = channel;
    const auto& source = sources_[static_cast<std::size_t>(channel)];
    s.volts = source ? source(s.cycle) : fixed_volts_[static_cast<std::size_t>(channel)];
    s.millivolts = s.volts > 0 ? static_cast<std::uint32_t>(std::lround(s.volts * 1000.0)) : 0;
    ++samples_;
    avr_raise_irq(irq_base_ + channel, s.millivolts);
    for (auto& fn : listeners_) fn(s);
}

}  // namespace avrbench
