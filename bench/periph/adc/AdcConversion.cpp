// The ADC's conversions (ATmega328P §24, ATmega2560 §26, ATmega32 "Analog to
// Digital Converter").
//
// simavr 1.6's ADC departs from the datasheet in many ways; the bench takes
// over the conversion engine (write hook on ADCSRA, read hooks on ADCL/ADCH,
// its own cycle timer) and keeps simavr's register layout and mux tables:
//  - input IRQs ADC_IRQ_ADC8..15 (the 2560's A8..A15) are dropped (simavr
//    keeps 8 voltages) and a conversion of ADC8..15 reads past that array;
//    here the module's IRQ array is replaced by one the bench owns (16
//    channels; periph/adc/Adc.cpp's analog sources, when set, take precedence for
//    single-ended channels);
//  - the result is computed when the firmware reads ADCL/ADCH, from the mux
//    and the voltage of that moment, and scaled by 1023 instead of 1024; on
//    the part it is sampled at the sample-and-hold point of the conversion
//    (1.5 ADC clocks after its start, 13.5 for the first conversion, 2 for an
//    auto-triggered one: §24.4 Table 24-1) from the channel latched at its
//    start ("once the conversion starts, the channel and reference selection
//    is locked"), and ADC = VIN * 1024 / VREF (§24.7);
//  - a conversion takes exactly 13 (first: 25) ADC clocks from the ADSC
//    write: the part starts it at the next rising edge of the ADC clock,
//    whose prescaler runs from ADEN (§24.4); free running conversions are
//    re-armed from the cycle at which the timer was processed, so they drift;
//  - auto-trigger sources other than free running are not implemented (a
//    warning, then nothing); the ATmega32 has no ADATE at all in simavr;
//  - writing a one to ADIF does not clear it; enabling ADIE with ADIF set
//    does not interrupt; the ADCL/ADCH read lock ("if ADCL has been read,
//    and a conversion completes before ADCH is read, neither register is
//    updated and the result from the conversion is lost") is not modelled;
//  - entering ADC Noise Reduction mode does not start a conversion (§24.6);
//  - with no supply voltages set, VREF is taken as 3.3 V and warnings are
//    logged: the bench assumes VCC = AVCC = AREF = 5 V unless set.
//
// The ADC clock: the prescaler counts from the ADEN write; its output rises
// half a period later and then every period (this half period is the ".5" of
// the 13.5-clock auto-triggered conversion, whose trigger resets the prescaler).
#include <algorithm>
#include <vector>

extern "C" {
#include <avr_acomp.h>
#include <avr_adc.h>
#include <avr_extint.h>
#include <avr_timer.h>
#include <sim_cycle_timers.h>
#include <sim_io.h>
#include <sim_irq.h>
}

#include "periph/Fixes.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {
namespace {

class AdcConversion final : public Fix {
public:
    AdcConversion(avr_t* avr, avr_adc_t* adc) : avr_(avr), adc_(adc) {
        if (avr->vcc == 0) avr->vcc = 5000;  // assumed: 5 V board (Arduino UNO / Mega)
        if (avr->avcc == 0) avr->avcc = 5000;
        if (avr->aref == 0) avr->aref = 5000;  // assumed: AREF tied to AVCC

        // The bench's own IRQ array for the module (see above).
        original_irq_ = adc->io.irq;
        static const char* names[ADC_IRQ_COUNT] = {
            "16<adc0",  "16<adc1",  "16<adc2",  "16<adc3",  "16<adc4",   "16<adc5",       "16<adc6",
            "16<adc7",  "16<adc8",  "16<adc9",  "16<adc10", "16<adc11",  "16<adc12",      "16<adc13",
            "16<adc14", "16<adc15", "16<temp",  "<trigger_in", ">trigger_out"};
        irq_ = avr_alloc_irq(&avr->irq_pool, 0, ADC_IRQ_COUNT, names);
        adc->io.irq = irq_;
        for (int i = 0; i <= ADC_IRQ_TEMP; ++i) avr_irq_register_notify(irq_ + i, &on_input, this);
        original_reset_ = adc->io.reset;
        adc->io.reset = &on_reset;
        FixState<AdcConversion>::add(&adc->io, this);

        // m32: ADATE is ADCSRA bit 5 and ADTS2:0 are SFIOR bits 7:5; simavr
        // declares neither.
        if (adc->adate.reg == 0) {
            adate_ = avr_regbit_t{};
            adate_.reg = adc->r_adcsra;
            adate_.bit = 5;
            adate_.mask = 1;
            adts_reg_ = 0x50;  // SFIOR
            adts_shift_ = 5;
        } else {
            adate_ = adc->adate;
            adts_reg_ = adc->adts[0].reg;
            adts_shift_ = adc->adts[0].bit;
        }

        hooks_.push_back(std::make_unique<IoWriteHook>(avr, adc->r_adcsra, &on_adcsra_write, this));
        read_hooks_.push_back(std::make_unique<IoReadHook>(avr, adc->r_adcl, &on_read, this));
        read_hooks_.push_back(std::make_unique<IoReadHook>(avr, adc->r_adch, &on_read, this));
        if (adc->r_adcsrb != 0) {
            hooks_.push_back(std::make_unique<IoWriteHook>(avr, adc->r_adcsrb, &on_plain_write, this));
        }
        connect_triggers();
        add_sleep_entry_listener(avr, &on_sleep_entry, this);
    }

    ~AdcConversion() override {
        remove_sleep_entry_listener(avr_, this);
        hooks_.clear();
        read_hooks_.clear();
        for (auto& t : triggers_) avr_irq_unregister_notify(t.vector->irq + AVR_INT_IRQ_PENDING, &on_trigger, &t);
        avr_cycle_timer_cancel(avr_, &on_timer, this);
        adc_->io.reset = original_reset_;
        adc_->io.irq = original_irq_;
        avr_free_irq(irq_, ADC_IRQ_COUNT);
        FixState<AdcConversion>::remove(&adc_->io);
    }

private:
    struct Trigger {
        AdcConversion* self;
        int adts;  // ADTS2:0 value selecting it
        avr_int_vector_t* vector;
        bool flag_high = false;
    };

    // ADTS2:0 (328P Table 24-6, 2560 Table 26-6, m32 Table 86): 1 analog
    // comparator, 2 INT0, 3 Timer0 compare match (A), 4 Timer0 overflow,
    // 5 Timer1 compare match B, 6 Timer1 overflow, 7 Timer1 capture.
    void connect_triggers() {
        auto add = [&](int adts, avr_int_vector_t* v) {
            if (v != nullptr && v->vector != 0) triggers_.push_back(Trigger{this, adts, v});
        };
        if (auto* ac = find_io_module(avr_, "ac")) add(1, &reinterpret_cast<avr_acomp_t*>(ac)->ac);
        if (auto* ext = find_io_module(avr_, "extint")) add(2, &reinterpret_cast<avr_extint_t*>(ext)->eint[0].vector);
        if (auto* t0 = reinterpret_cast<avr_timer_t*>(find_io_module(avr_, "timer", '0'))) {
            add(3, &t0->comp[AVR_TIMER_COMPA].interrupt);
            add(4, &t0->overflow);
        }
        if (auto* t1 = reinterpret_cast<avr_timer_t*>(find_io_module(avr_, "timer", '1'))) {
            add(5, &t1->comp[AVR_TIMER_COMPB].interrupt);
            add(6, &t1->overflow);
            add(7, &t1->icr);
        }
        for (auto& t : triggers_) {
            t.flag_high = t.vector->raised.reg != 0 && avr_regbit_get(avr_, t.vector->raised) != 0;
            avr_irq_register_notify(t.vector->irq + AVR_INT_IRQ_PENDING, &on_trigger, &t);
        }
    }

    bool enabled() const { return avr_regbit_get(avr_, adc_->aden) != 0; }
    bool auto_trigger() const { return avr_regbit_get(avr_, adate_) != 0; }
    int trigger_source() const {
        if (adts_reg_ == 0) return 0;
        return (avr_->data[adts_reg_] >> adts_shift_) & 0x7;
    }
    avr_cycle_count_t adc_clock_period() const {
        const unsigned adps = avr_regbit_get_array(avr_, adc_->adps, 3);
        return adps == 0 ? 2 : (avr_cycle_count_t{1} << adps);  // ADPS 000 and 001: division factor 2
    }

    // The first rising edge of the ADC clock strictly after `t`.
    avr_cycle_count_t next_edge_after(avr_cycle_count_t t) const {
        const avr_cycle_count_t p = adc_clock_period();
        const avr_cycle_count_t first = prescaler_start_ + p / 2;
        if (t < first) return first;
        return first + ((t - first) / p + 1) * p;
    }

    // Latches channel and reference and starts a conversion; the caller arms
    // the timer (schedule(), or the timer callback's return value).
    void start(avr_cycle_count_t start_edge, avr_cycle_count_t sample_delay, avr_cycle_count_t duration) {
        converting_ = true;
        channel_ = avr_regbit_get_array(avr_, adc_->mux, 6) & 0x3F;
        ref_ = avr_regbit_get_array(avr_, adc_->ref, 3);
        sample_at_ = start_edge + sample_delay;
        done_at_ = start_edge + duration;
        sampled_ = false;
        avr_regbit_set(avr_, adc_->adsc);
        // simavr's protocol for analog sources (avr_adc.h): ADC_IRQ_OUT_TRIGGER
        // carries the mux descriptor when a conversion starts; `first` says
        // whether it is the first one after ADEN (periph/adc/Adc.cpp reads both).
        adc_->first = first_ ? 1 : 0;
        union {
            avr_adc_mux_t mux;
            std::uint32_t v;
        } e = {adc_->muxmode[channel_]};
        avr_raise_irq(irq_ + ADC_IRQ_OUT_TRIGGER, e.v);
    }

    void start_from_adsc(avr_cycle_count_t t) {
        const avr_cycle_count_t p = adc_clock_period();
        const avr_cycle_count_t edge = next_edge_after(t);
        if (first_) {
            start(edge, p * 27 / 2, 25 * p);  // first conversion: S&H 13.5, done 25 (Table 24-1)
        } else {
            start(edge, p * 3 / 2, 13 * p);  // normal: S&H 1.5, done 13
        }
        first_ = false;
        schedule(sample_at_);
    }

    void schedule(avr_cycle_count_t at) {
        const avr_cycle_count_t now = avr_->cycle;
        avr_cycle_timer_register(avr_, at > now ? at - now : 0, &on_timer, this);
    }

    static avr_cycle_count_t on_timer(avr_t* avr, avr_cycle_count_t when, void* param) {
        auto* self = static_cast<AdcConversion*>(param);
        if (!self->converting_) return 0;
        (void)avr;
        if (!self->sampled_) {
            self->sample_value_ = self->convert();
            self->sampled_ = true;
            return self->done_at_ > when ? self->done_at_ : when + 1;
        }
        self->complete(when);
        // Free running: the next conversion started at `when`; sample next.
        return self->converting_ ? self->sample_at_ : 0;
    }

    void complete(avr_cycle_count_t when) {
        converting_ = false;
        adc_->first = 0;
        if (!locked_) {
            result_ = sample_value_;
            publish();
            adc_->read_status = 0;  // simavr's "result not read yet" (periph/adc/Adc.cpp reads it)
        }
        avr_raise_interrupt(avr_, &adc_->adc);  // ADIF
        const bool free_running = auto_trigger() && trigger_source() == 0;
        if (free_running && enabled()) {
            // "In Free Running mode, a new conversion will be started
            // immediately after the conversion completes, while ADSC remains high."
            const avr_cycle_count_t p = adc_clock_period();
            start(when, p * 3 / 2, 13 * p);
        } else {
            avr_regbit_clear(avr_, adc_->adsc);
        }
    }

    // The 10-bit result (two's complement for differential channels) of the
    // latched channel and reference, from the inputs at the sample instant.
    std::uint16_t convert() const {
        const avr_adc_mux_t mux = adc_->muxmode[channel_];
        const std::uint16_t ref = adc_->ref_values[ref_ < 7 ? ref_ : 0];
        double vref = 0;
        switch (ref) {
            case ADC_VREF_AREF: vref = avr_->aref; break;
            case ADC_VREF_VCC: vref = avr_->vcc; break;
            case ADC_VREF_AVCC: vref = avr_->avcc; break;
            default: vref = ref; break;
        }
        if (vref <= 0) return 0;
        auto clamp = [](double v, double lo, double hi) { return std::min(std::max(v, lo), hi); };
        switch (mux.kind) {
            case ADC_MUX_SINGLE:  // §24.7: ADC = VIN * 1024 / VREF
                return static_cast<std::uint16_t>(clamp(values_[mux.src & 15] * 1024.0 / vref, 0, 1023));
            case ADC_MUX_REF:  // bandgap / GND (mV)
                return static_cast<std::uint16_t>(clamp(mux.src * 1024.0 / vref, 0, 1023));
            case ADC_MUX_DIFF: {  // §24.7: ADC = (VPOS - VNEG) * GAIN * 512 / VREF
                const double gain = mux.gain == 0 ? 1 : mux.gain;
                const double v = (static_cast<double>(values_[mux.src & 15]) - values_[mux.diff & 15]) * gain * 512.0 / vref;
                const auto code = static_cast<int>(clamp(v, -512, 511));
                return static_cast<std::uint16_t>(code & 0x3FF);
            }
            case ADC_MUX_TEMP:
                return static_cast<std::uint16_t>(temp_ & 0x3FF);
            default:
                return 0;
        }
    }

    // ADCL/ADCH hold the result as ADLAR presents it ("changing the ADLAR bit
    // will affect the ADC Data Register immediately").
    void publish() {
        const bool left = avr_regbit_get(avr_, adc_->adlar) != 0;
        published_left_ = left;
        const std::uint16_t v = left ? static_cast<std::uint16_t>(result_ << 6) : result_;
        avr_->data[adc_->r_adcl] = static_cast<std::uint8_t>(v & 0xFF);
        avr_->data[adc_->r_adch] = static_cast<std::uint8_t>(v >> 8);
    }

    static std::uint8_t on_read(IoReadHook& hook, avr_t* avr, avr_io_addr_t addr) {
        auto* self = static_cast<AdcConversion*>(hook.context());
        // The data registers were written at the end of the conversion (an
        // analog model such as periph/adc/Adc.cpp may have replaced them since);
        // only an ADLAR change since then re-presents the result.
        if ((avr_regbit_get(avr, self->adc_->adlar) != 0) != self->published_left_) self->publish();
        if (addr == self->adc_->r_adcl) {
            self->locked_ = true;  // §24.2: ADCL read blocks updates until ADCH is read
            self->adc_->read_status = 1;
        } else {
            self->locked_ = false;
            self->adc_->read_status = 2;
        }
        return avr->data[addr];
    }

    static void on_adcsra_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        auto* self = static_cast<AdcConversion*>(hook.context());
        avr_adc_t* adc = self->adc_;
        const bool was_enabled = self->enabled();
        const std::uint8_t adif = static_cast<std::uint8_t>(adc->adc.raised.mask << adc->adc.raised.bit);
        const std::uint8_t adsc = static_cast<std::uint8_t>(adc->adsc.mask << adc->adsc.bit);
        const std::uint8_t old = avr->data[addr];
        // ADIF: cleared by writing a one, kept otherwise; ADSC: a zero has no effect.
        std::uint8_t v = static_cast<std::uint8_t>((value & ~adif) | (old & adif));
        if (self->converting_) v |= adsc;
        avr->data[addr] = v;
        if ((value & adif) != 0 && (old & adif) != 0) {
            if (adc->adc.pending) unpend_interrupt(avr, &adc->adc);
            avr->data[addr] &= static_cast<std::uint8_t>(~adif);
            avr_raise_irq(adc->adc.irq + AVR_INT_IRQ_PENDING, 0);
        }
        const avr_cycle_count_t now = avr->cycle;
        if (!was_enabled && self->enabled()) {
            self->prescaler_start_ = now;
            self->first_ = true;
        }
        if (was_enabled && !self->enabled()) {
            // "Turning the ADC off while a conversion is in progress will terminate this conversion."
            self->converting_ = false;
            avr_cycle_timer_cancel(avr, &on_timer, self);
            avr_regbit_clear(avr, adc->adsc);
        }
        if (self->enabled() && !self->converting_ && (value & adsc) != 0) self->start_from_adsc(now);
        sync_enables(avr, addr);
    }

    // §10.4 / §24.6: "If the ADC is enabled, a conversion starts
    // automatically when this mode [ADC Noise Reduction] is entered" (single
    // conversion mode, no conversion in progress).
    static avr_cycle_count_t on_sleep_entry(void* context, avr_t* avr, std::uint8_t mode) {
        auto* self = static_cast<AdcConversion*>(context);
        if (mode != kSleepAdcNoiseReduction || !self->enabled() || self->converting_ || self->auto_trigger()) return 0;
        self->start_from_adsc(avr->cycle);
        return self->sample_at_;
    }

    static void on_plain_write(IoWriteHook& hook, avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
        (void)hook;
        avr->data[addr] = value;
    }

    // A source's interrupt flag went from 0 to 1: "a positive edge on the
    // selected trigger signal" starts a conversion (prescaler reset), unless
    // one is running.
    static void on_trigger(avr_irq_t*, std::uint32_t value, void* param) {
        auto& t = *static_cast<Trigger*>(param);
        const bool rising = value != 0 && !t.flag_high;
        t.flag_high = value != 0;
        if (!rising) return;
        AdcConversion* self = t.self;
        if (!self->enabled() || !self->auto_trigger() || self->trigger_source() != t.adts || self->converting_) return;
        const avr_cycle_count_t now = self->avr_->cycle;
        const avr_cycle_count_t p = self->adc_clock_period();
        self->prescaler_start_ = now;
        // Table 24-1: auto-triggered: sample-and-hold at 2, done at 13.5 ADC clocks.
        self->start(now, 2 * p, p * 27 / 2);
        self->first_ = false;
        self->schedule(self->sample_at_);
    }

    static void on_input(avr_irq_t* irq, std::uint32_t value, void* param) {
        auto* self = static_cast<AdcConversion*>(param);
        const int i = static_cast<int>(irq - self->irq_);
        if (i < 16) {
            self->values_[i] = value;
        } else {
            self->temp_ = value;
        }
    }

    static void on_reset(avr_io_t* io) {
        AdcConversion* self = FixState<AdcConversion>::find(io);
        // simavr's reset re-registers its notify on the module's IRQs: let it
        // find its own array, not the bench's.
        self->adc_->io.irq = self->original_irq_;
        self->original_reset_(io);
        self->adc_->io.irq = self->irq_;
        self->converting_ = false;
        self->locked_ = false;
        self->result_ = 0;
        for (auto& t : self->triggers_) t.flag_high = false;
    }

    avr_t* avr_;
    avr_adc_t* adc_;
    avr_irq_t* original_irq_ = nullptr;
    avr_irq_t* irq_ = nullptr;
    void (*original_reset_)(avr_io_t*) = nullptr;
    avr_regbit_t adate_{};
    avr_io_addr_t adts_reg_ = 0;
    unsigned adts_shift_ = 0;
    std::vector<std::unique_ptr<IoWriteHook>> hooks_;
    std::vector<std::unique_ptr<IoReadHook>> read_hooks_;
    std::vector<Trigger> triggers_;

    std::uint32_t values_[16] = {};
    std::uint32_t temp_ = 0;
    avr_cycle_count_t prescaler_start_ = 0;
    bool first_ = true;
    bool converting_ = false;
    bool sampled_ = false;
    bool locked_ = false;
    bool published_left_ = false;
    unsigned channel_ = 0;
    unsigned ref_ = 0;
    avr_cycle_count_t sample_at_ = 0;
    avr_cycle_count_t done_at_ = 0;
    std::uint16_t sample_value_ = 0;
    std::uint16_t result_ = 0;
};

}  // namespace

std::unique_ptr<Fix> install_adc_conversion(avr_t* avr) {
    avr_io_t* io = find_io_module(avr, "adc");
    if (io == nullptr) return nullptr;
    return std::make_unique<AdcConversion>(avr, reinterpret_cast<avr_adc_t*>(io));
}

}  // namespace avrbench
