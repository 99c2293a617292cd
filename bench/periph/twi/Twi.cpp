#include "periph/twi/Twi.hpp"

#include <algorithm>
#include <cstring>

#include "core/CycleAt.hpp"
#include "core/Scheduler.hpp"
#include "periph/timer/CompareOutputPins.hpp"
#include "periph/Fix.hpp"

extern "C" {
#include <avr_twi.h>
#include <sim_avr.h>
#include <sim_interrupts.h>
#include <sim_irq.h>
}

namespace avrbench {
namespace {

// TWCR bits, identical on the three parts (328P §22.9.2, 2560 §24.9.2, m32 §22.9.2).
constexpr std::uint8_t kTwint = 1u << 7;
constexpr std::uint8_t kTwea = 1u << 6;
constexpr std::uint8_t kTwsta = 1u << 5;
constexpr std::uint8_t kTwsto = 1u << 4;
constexpr std::uint8_t kTwwc = 1u << 3;
constexpr std::uint8_t kTwen = 1u << 2;
constexpr std::uint8_t kTwie = 1u << 0;
constexpr std::uint8_t kWritableControl = kTwea | kTwsta | kTwsto | kTwen | kTwie;
constexpr std::uint8_t kPrescalerBits = 0x03;  // TWSR TWPS1:0; bit 2 reserved
constexpr std::uint8_t kStatusBits = 0xF8;

// Status codes (328P Tables 22-2 master transmitter, 22-3 master receiver,
// 22-4 slave receiver, 22-5 slave transmitter, 22-6 miscellaneous).
namespace status {
constexpr std::uint8_t kStart = 0x08;
constexpr std::uint8_t kRepeatedStart = 0x10;
constexpr std::uint8_t kMtSlaAck = 0x18;
constexpr std::uint8_t kMtSlaNack = 0x20;
constexpr std::uint8_t kMtDataAck = 0x28;
constexpr std::uint8_t kMtDataNack = 0x30;
constexpr std::uint8_t kMrSlaAck = 0x40;
constexpr std::uint8_t kMrSlaNack = 0x48;
constexpr std::uint8_t kMrDataAck = 0x50;
constexpr std::uint8_t kMrDataNack = 0x58;
constexpr std::uint8_t kSrSlaAck = 0x60;
constexpr std::uint8_t kSrGeneralCallAck = 0x70;
constexpr std::uint8_t kSrDataAck = 0x80;
constexpr std::uint8_t kSrDataNack = 0x88;
constexpr std::uint8_t kSrGeneralDataAck = 0x90;
constexpr std::uint8_t kSrGeneralDataNack = 0x98;
constexpr std::uint8_t kSrStopOrRestart = 0xA0;
constexpr std::uint8_t kStSlaAck = 0xA8;
constexpr std::uint8_t kStDataAck = 0xB8;
constexpr std::uint8_t kStDataNack = 0xC0;
constexpr std::uint8_t kStLastDataAck = 0xC8;
constexpr std::uint8_t kNoState = 0xF8;
}  // namespace status

// After these the slave is switched to the not addressed mode once the
// firmware clears TWINT (Tables 22-4 and 22-5, "Next action" column).
bool ends_slave_transfer(std::uint8_t s) {
    return s == status::kSrDataNack || s == status::kSrGeneralDataNack || s == status::kSrStopOrRestart ||
           s == status::kStDataNack || s == status::kStLastDataAck;
}

}  // namespace

TwiPins twi_pins(const std::string& mcu_type) {
    // Pin descriptions: 328P §1.1 (PC4 SDA, PC5 SCL), 2560 §1.1 (PD1 SDA, PD0
    // SCL), ATmega32 §1.1 (PC1 SDA, PC0 SCL).
    if (mcu_type == "atmega328p" || mcu_type == "atmega328" || mcu_type == "atmega168" || mcu_type == "atmega88" ||
        mcu_type == "atmega48" || mcu_type == "atmega168p" || mcu_type == "atmega88p" || mcu_type == "atmega48p") {
        return {"PC4", "PC5"};
    }
    if (mcu_type == "atmega2560" || mcu_type == "atmega1280" || mcu_type == "atmega1281" || mcu_type == "atmega2561") {
        return {"PD1", "PD0"};
    }
    if (mcu_type == "atmega32" || mcu_type == "atmega16") return {"PC1", "PC0"};
    return {};
}

std::unique_ptr<Twi> Twi::install(avr_t* avr, const std::string& mcu_type, Scheduler& scheduler,
                                  std::string owner_name) {
    if (auto* io = find_io_module(avr, "twi")) {
        auto* module = reinterpret_cast<avr_twi_t*>(io);
        const Registers r{module->r_twbr, module->r_twsr, module->r_twar,
                          module->r_twdr, module->r_twcr, module->r_twamr};
        return std::unique_ptr<Twi>(
            new Twi(avr, r, &module->twi, false, scheduler, std::move(owner_name), twi_pins(mcu_type)));
    }
    if (mcu_type == "atmega32") {
        // Registers from the ATmega32 datasheet's register summary (I/O
        // addresses + 0x20); TWI is interrupt vector 19 (§11, Table 18).
        const Registers r{0x20, 0x21, 0x22, 0x23, 0x56, 0};
        auto* vector = new avr_int_vector_t{};
        vector->vector = 19;
        vector->enable = AVR_IO_REGBIT(0x56, 0);  // TWIE
        vector->raised = AVR_IO_REGBIT(0x56, 7);  // TWINT
        vector->raise_sticky = 1;                 // the ISR does not clear TWINT (§22.9.2)
        avr_register_vector(avr, vector);
        return std::unique_ptr<Twi>(new Twi(avr, r, vector, true, scheduler, std::move(owner_name), twi_pins(mcu_type)));
    }
    return nullptr;
}

Twi::Twi(avr_t* avr, Registers registers, avr_int_vector_t* vector, bool own_vector, Scheduler& scheduler,
         std::string owner_name, TwiPins pins)
    : avr_(avr),
      registers_(registers),
      vector_(vector),
      own_vector_(own_vector),
      scheduler_(scheduler),
      owner_name_(std::move(owner_name)),
      own_bus_(std::make_unique<TwiBus>()),
      pins_(std::move(pins)) {
    control_hook_ = std::make_unique<IoWriteHook>(avr, registers_.twcr, &Twi::on_control_write, this);
    data_hook_ = std::make_unique<IoWriteHook>(avr, registers_.twdr, &Twi::on_data_write, this);
    status_hook_ = std::make_unique<IoWriteHook>(avr, registers_.twsr, &Twi::on_status_write, this);
    bus_ = own_bus_.get();
    bus_->add(*this);
    reset();
}

Twi::~Twi() {
    if (bus_ != nullptr) bus_->remove(*this);
    control_hook_.reset();
    data_hook_.reset();
    status_hook_.reset();
    if (own_vector_) {
        avr_int_table_p table = &avr_->interrupts;
        auto* end = table->vector + table->vector_count;
        auto* it = std::find(table->vector, end, vector_);
        if (it != end) {
            std::copy(it + 1, end, it);
            --table->vector_count;
        }
        avr_free_irq(vector_->irq, AVR_INT_IRQ_COUNT);
        delete vector_;
    }
}

void Twi::attach(TwiBus& bus) {
    if (bus_ == &bus) return;
    if (bus_ != nullptr) bus_->remove(*this);
    bus_ = &bus;
    bus.add(*this);
}

void Twi::reset() {
    if (bus_ != nullptr) bus_->drop(*this);
    release_lines();
    addressed_ = transmitting_ = general_call_ = last_byte_ = start_pending_ = false;
    last_status_ = status::kNoState;
    avr_clear_interrupt(avr_, vector_);
    // Initial values: TWBR 0, TWCR 0, TWSR 0xF8, TWDR 0xFF, TWAR 0xFE, TWAMR 0
    // (328P §22.9, register descriptions).
    avr_->data[registers_.twbr] = 0;
    avr_->data[registers_.twcr] = 0;
    avr_->data[registers_.twsr] = status::kNoState;
    avr_->data[registers_.twdr] = 0xFF;
    avr_->data[registers_.twar] = 0xFE;
    if (registers_.twamr != 0) avr_->data[registers_.twamr] = 0;
}

bool Twi::control_bit(std::uint8_t mask) const { return (avr_->data[registers_.twcr] & mask) != 0; }

void Twi::set_control_bit(std::uint8_t mask, bool on) {
    auto& r = avr_->data[registers_.twcr];
    r = static_cast<std::uint8_t>(on ? (r | mask) : (r & ~mask));
}

bool Twi::interrupt_flag() const { return control_bit(kTwint); }
std::uint8_t Twi::status() const { return avr_->data[registers_.twsr] & kStatusBits; }
std::uint8_t Twi::data() const { return avr_->data[registers_.twdr]; }
void Twi::set_data(std::uint8_t value) { avr_->data[registers_.twdr] = value; }
std::uint8_t Twi::own_address_register() const { return avr_->data[registers_.twar]; }
std::uint8_t Twi::address_mask_register() const {
    return registers_.twamr != 0 ? avr_->data[registers_.twamr] : 0;
}

void Twi::set_status_only(std::uint8_t s) {
    auto& r = avr_->data[registers_.twsr];
    r = static_cast<std::uint8_t>((r & kPrescalerBits) | (s & kStatusBits));
}

void Twi::post_status(std::uint8_t s) {
    last_status_ = s;
    set_status_only(s);
    avr_raise_interrupt(avr_, vector_);  // sets TWINT; pends TWI_vect when TWIE
}

void Twi::clear_interrupt_flag() {
    // The vector is raise_sticky (the ISR leaves TWINT alone), so simavr's
    // clear leaves the flag: clear it here.
    avr_clear_interrupt(avr_, vector_);
    set_control_bit(kTwint, false);
    set_status_only(status::kNoState);   // Table 22-6: 0xF8 while TWINT = 0
}

Cycle Twi::scl_period_cycles() const {
    // §22.5.2: SCL frequency = CPU clock / (16 + 2 * TWBR * 4^TWPS).
    const unsigned prescaler = 1u << (2 * (avr_->data[registers_.twsr] & kPrescalerBits));
    return 16 + 2ull * avr_->data[registers_.twbr] * prescaler;
}

void Twi::on_control_write(IoWriteHook& hook, avr_t* avr, std::uint16_t addr, std::uint8_t value) {
    auto& self = *static_cast<Twi*>(hook.context());
    const std::uint8_t before = avr->data[addr];
    avr->data[addr] = static_cast<std::uint8_t>((value & kWritableControl) | (before & (kTwint | kTwwc)));
    const bool was_enabled = (before & kTwen) != 0;
    if (!(value & kTwen)) {
        if (was_enabled) self.disable();
        return;
    }
    if (value & kTwint) {
        // Writing one clears TWINT and starts whatever TWSTA/TWSTO/TWDR ask for.
        self.clear_interrupt_flag();
        self.act();
        return;
    }
    // TWIE changed while TWINT stays set: simavr decides "pending" only when
    // a flag is raised, so follow the enable bit here.
    if (self.interrupt_flag()) {
        const bool enabled = (value & kTwie) != 0;
        if (enabled && !self.vector_->pending) {
            avr_raise_interrupt(avr, self.vector_);
        } else if (!enabled && self.vector_->pending) {
            avr_clear_interrupt(avr, self.vector_);
            self.set_control_bit(kTwint, true);
        }
    }
}

void Twi::on_data_write(IoWriteHook& hook, avr_t* avr, std::uint16_t addr, std::uint8_t value) {
    auto& self = *static_cast<Twi*>(hook.context());
    // §22.9.2 TWWC: writing TWDR while TWINT is low is a write collision;
    // the byte on its way is not replaced.
    if (!self.interrupt_flag() && self.control_bit(kTwen)) {
        self.set_control_bit(kTwwc, true);
        return;
    }
    self.set_control_bit(kTwwc, false);
    avr->data[addr] = value;
}

void Twi::on_status_write(IoWriteHook&, avr_t* avr, std::uint16_t addr, std::uint8_t value) {
    // Only the prescaler bits are writable (§22.9.3).
    avr->data[addr] = static_cast<std::uint8_t>((avr->data[addr] & ~kPrescalerBits) | (value & kPrescalerBits));
}

void Twi::disable() {
    // §22.9.2 TWEN: "writing it to zero switches the TWI off, and all TWI
    // transmissions are terminated, regardless of any ongoing operation".
    bus_->drop(*this);
    release_lines();
    addressed_ = transmitting_ = general_call_ = last_byte_ = start_pending_ = false;
    clear_interrupt_flag();
    last_status_ = status::kNoState;
}

void Twi::draw(Line line, bool low, Cycle at) {
    if (line_low_[line] == low) return;
    line_low_[line] = low;
    if (line_driver_[line] == -2) {
        CompareOutputPins* outputs = CompareOutputPins::of(avr_);
        const std::string& name = line == kSda ? pins_.sda : pins_.scl;
        line_driver_[line] = outputs != nullptr && name.size() == 3 ? outputs->add_forced_output(name[1], name[2] - '0') : -1;
    }
    const int driver = line_driver_[line];
    if (driver < 0) return;
    scheduler_.at(at, [this, driver, low](Cycle cycle) {
        CompareOutputPins* outputs = CompareOutputPins::of(avr_);
        if (outputs == nullptr) return;
        const CycleAt stamp(avr_, cycle);
        outputs->set(driver, low, false);  // pulled low, or let go to the pull-ups
    });
}

void Twi::release_lines() {
    // At once: a reset or TWEN = 0 lets both lines go (§22.9.2).
    for (const Line line : {kSda, kScl}) {
        line_low_[line] = false;
        if (line_driver_[line] < 0) continue;
        if (CompareOutputPins* outputs = CompareOutputPins::of(avr_)) outputs->set(line_driver_[line], false, false);
    }
}

void Twi::act() {
    const bool start = control_bit(kTwsta);
    const bool stop = control_bit(kTwsto);
    TwiBus& bus = *bus_;
    if (bus.master_ == this) {
        if (bus.in_flight_ || bus.waiting_ != TwiBus::Op::None) return;  // the bus is busy with our last request
        if (stop) {
            bus.request(*this, TwiBus::Op::Stop, start);
            return;
        }
        if (start) {
            bus.request(*this, TwiBus::Op::Start);
            return;
        }
        switch (last_status_) {
        case status::kStart:
        case status::kRepeatedStart:
            bus.request(*this, TwiBus::Op::Address);
            return;
        case status::kMtSlaAck:
        case status::kMtSlaNack:
        case status::kMtDataAck:
        case status::kMtDataNack:
            bus.request(*this, TwiBus::Op::Write);
            return;
        case status::kMrSlaAck:
        case status::kMrDataAck:
            bus.request(*this, TwiBus::Op::Read);
            return;
        default:
            return;  // 0x48 / 0x58: only a (repeated) START or a STOP continues
        }
    }
    if (addressed_) {
        if (ends_slave_transfer(last_status_)) {
            addressed_ = transmitting_ = general_call_ = false;
        } else if (transmitting_) {
            // Table 22-5: TWDR now holds the next byte; TWEA = 0 makes it the last.
            last_byte_ = !control_bit(kTwea);
        }
        bus.slave_released(*this);
    }
    if (stop) {
        // Not a master: TWSTO recovers from an error condition, releasing the lines (Table 22-6).
        set_control_bit(kTwsto, false);
        addressed_ = transmitting_ = general_call_ = false;
        bus.slave_released(*this);
    }
    if (start) bus.request(*this, TwiBus::Op::Start);
}

// ---------------------------------------------------------------- TwiBus

TwiBus::~TwiBus() {
    // Members of a board's bus go back to their own when the board's goes first.
    for (Twi* t : members_) {
        if (t->bus_ != this) continue;
        t->bus_ = t->own_bus_.get() != this ? t->own_bus_.get() : nullptr;
        if (t->bus_ != nullptr) t->bus_->add(*t);
    }
}

void TwiBus::add(Twi& twi) {
    if (std::find(members_.begin(), members_.end(), &twi) == members_.end()) members_.push_back(&twi);
}

void TwiBus::remove(Twi& twi) {
    drop(twi);
    members_.erase(std::remove(members_.begin(), members_.end(), &twi), members_.end());
    // A module leaving a shared bus goes back to its own.
    if (twi.bus_ == this) twi.bus_ = nullptr;
}

void TwiBus::drop(Twi& twi) {
    twi.start_pending_ = false;
    if (master_ == &twi) {
        ++generation_;  // an operation still on its way is void
        in_flight_ = false;
        waiting_ = Op::None;
        if (slave_ != nullptr) slave_->addressed_ = slave_->transmitting_ = slave_->general_call_ = false;
        slave_ = nullptr;
        master_ = nullptr;
        session_ = false;
        start_waiting_master();
    } else if (slave_ == &twi) {
        slave_ = nullptr;
        if (waiting_ != Op::None) {
            const Op op = waiting_;
            waiting_ = Op::None;
            begin(op, waiting_then_start_);
        }
    }
}

bool TwiBus::slave_holds_scl() const { return slave_ != nullptr && slave_->interrupt_flag(); }

void TwiBus::request(Twi& master, Op op, bool then_start) {
    // The other modules' state (a slave holding SCL) as of the master's time.
    for (Twi* t : members_) {
        if (t != &master) t->sync();
    }
    if (op == Op::Start && master_ != &master) {
        if (master_ != nullptr) {
            master.start_pending_ = true;  // §22.7.5: the START waits for a STOP on the bus
            return;
        }
        master_ = &master;
        session_ = false;
    }
    if (slave_holds_scl()) {
        waiting_ = op;
        waiting_then_start_ = then_start;
        return;
    }
    begin(op, then_start);
}

void TwiBus::draw(Op op) {
    Twi& m = *master_;
    const Cycle t0 = m.avr_->cycle;
    const Cycle period = m.scl_period_cycles();
    const Cycle quarter = period / 4;
    switch (op) {
    case Op::Start:
        // From idle both lines are up already; a repeated START first lets
        // SDA and then SCL go (Figure 22-6, "REPEATED START").
        m.draw(Twi::kSda, false, t0);
        m.draw(Twi::kScl, false, t0 + quarter);
        m.draw(Twi::kSda, true, t0 + 2 * quarter);
        m.draw(Twi::kScl, true, t0 + period);
        return;
    case Op::Address:
    case Op::Write:
    case Op::Read: {
        // Eight bits MSB first, then the receiver's ACK (low) or NACK; each
        // bit changes SDA while SCL is low, SCL is high for the middle half.
        std::uint8_t byte = 0xFF;
        bool acked = false;
        if (op == Op::Read) {
            if (slave_ != nullptr && slave_->addressed_ && slave_->transmitting_) byte = slave_->data();
            acked = m.control_bit(kTwea);
        } else if (op == Op::Address) {
            byte = m.data();
            bool general_call = false;
            acked = find_slave(byte, general_call) != nullptr;
        } else {
            byte = m.data();
            acked = slave_ != nullptr && slave_->addressed_ && !slave_->transmitting_ && slave_->control_bit(kTwea);
        }
        for (int bit = 0; bit < 9; ++bit) {
            const bool high = bit < 8 ? ((byte >> (7 - bit)) & 1) != 0 : !acked;
            const Cycle begins = t0 + static_cast<Cycle>(bit) * period;
            m.draw(Twi::kSda, !high, begins + quarter);
            m.draw(Twi::kScl, false, begins + 2 * quarter);
            m.draw(Twi::kScl, true, begins + period);
        }
        return;
    }
    case Op::Stop:
        m.draw(Twi::kSda, true, t0 + quarter);
        m.draw(Twi::kScl, false, t0 + 2 * quarter);
        m.draw(Twi::kSda, false, t0 + 3 * quarter);
        return;
    case Op::None:
        return;
    }
}

void TwiBus::begin(Op op, bool then_start) {
    const bool byte = op == Op::Address || op == Op::Write || op == Op::Read;
    draw(op);
    const Cycle duration = (byte ? 9 : 1) * master_->scl_period_cycles();
    const std::uint64_t generation = ++generation_;
    in_flight_ = true;
    master_->scheduler_.after(duration, [this, op, then_start, generation](Cycle) {
        if (generation != generation_) return;
        in_flight_ = false;
        complete(op, then_start);
    });
}

Twi* TwiBus::find_slave(std::uint8_t address_byte, bool& general_call) const {
    const std::uint8_t address = address_byte >> 1;
    const bool read = (address_byte & 1) != 0;
    general_call = false;
    for (Twi* t : members_) {
        if (t == master_ || !t->control_bit(kTwen) || !t->control_bit(kTwea)) continue;
        // §22.9.6 TWAMR: a one masks (ignores) that address bit.
        const std::uint8_t mask = static_cast<std::uint8_t>(~(t->address_mask_register() >> 1) & 0x7F);
        const std::uint8_t own = static_cast<std::uint8_t>(t->own_address_register() >> 1);
        if ((address & mask) == (own & mask) && address != 0) return t;
        // §22.9.4 TWGCE: address 0 with a write is the general call.
        if (address == 0 && !read && (t->own_address_register() & 1)) {
            general_call = true;
            return t;
        }
    }
    return nullptr;
}

void TwiBus::complete(Op op, bool then_start) {
    Twi& m = *master_;
    for (Twi* t : members_) {
        if (t != &m) t->sync();
    }
    const Cycle now = m.avr_->cycle;
    switch (op) {
    case Op::Start: {
        const bool repeated = session_;
        if (repeated && slave_ != nullptr) {
            // Table 22-4: a receiving slave sees 0xA0; a transmitting one was
            // not supposed to be addressed any more and just lets go.
            if (slave_->addressed_ && !slave_->transmitting_) {
                slave_->post_status(status::kSrStopOrRestart);
            } else {
                slave_->addressed_ = slave_->transmitting_ = false;
                slave_ = nullptr;
            }
        }
        session_ = true;
        m.emit({repeated ? TwiEvent::Kind::RepeatedStart : TwiEvent::Kind::Start, now, 0, false});
        m.post_status(repeated ? status::kRepeatedStart : status::kStart);
        return;
    }
    case Op::Address: {
        const std::uint8_t sla = m.data();
        const bool read = (sla & 1) != 0;
        bool general_call = false;
        Twi* s = find_slave(sla, general_call);
        if (slave_ != nullptr && slave_ != s) slave_->addressed_ = slave_->transmitting_ = false;
        slave_ = s;
        if (s != nullptr) {
            s->addressed_ = true;
            s->transmitting_ = read;
            s->general_call_ = general_call;
            s->last_byte_ = false;
            s->post_status(read ? status::kStSlaAck : general_call ? status::kSrGeneralCallAck : status::kSrSlaAck);
        }
        m.emit({TwiEvent::Kind::Address, now, sla, s != nullptr});
        if (read) {
            m.post_status(s != nullptr ? status::kMrSlaAck : status::kMrSlaNack);
        } else {
            m.post_status(s != nullptr ? status::kMtSlaAck : status::kMtSlaNack);
        }
        return;
    }
    case Op::Write: {
        const std::uint8_t byte = m.data();
        bool acked = false;
        if (slave_ != nullptr && slave_->addressed_ && !slave_->transmitting_) {
            acked = slave_->control_bit(kTwea);
            slave_->set_data(byte);
            if (slave_->general_call_) {
                slave_->post_status(acked ? status::kSrGeneralDataAck : status::kSrGeneralDataNack);
            } else {
                slave_->post_status(acked ? status::kSrDataAck : status::kSrDataNack);
            }
        }
        m.emit({TwiEvent::Kind::Data, now, byte, acked});
        m.post_status(acked ? status::kMtDataAck : status::kMtDataNack);
        return;
    }
    case Op::Read: {
        const bool master_acks = m.control_bit(kTwea);
        std::uint8_t byte = 0xFF;  // nobody drives SDA: the pull-ups read as ones
        if (slave_ != nullptr && slave_->addressed_ && slave_->transmitting_) {
            byte = slave_->data();
            if (!master_acks) {
                slave_->post_status(status::kStDataNack);
            } else {
                slave_->post_status(slave_->last_byte_ ? status::kStLastDataAck : status::kStDataAck);
            }
        }
        m.set_data(byte);
        m.emit({TwiEvent::Kind::Data, now, byte, master_acks});
        m.post_status(master_acks ? status::kMrDataAck : status::kMrDataNack);
        return;
    }
    case Op::Stop: {
        if (slave_ != nullptr) {
            if (slave_->addressed_ && !slave_->transmitting_) {
                slave_->post_status(status::kSrStopOrRestart);
            } else {
                slave_->addressed_ = slave_->transmitting_ = false;
            }
        }
        slave_ = nullptr;
        m.emit({TwiEvent::Kind::Stop, now, 0, false});
        // §22.9.2 TWSTO: cleared by hardware once the STOP is on the bus; TWINT stays 0.
        m.set_control_bit(kTwsto, false);
        m.set_status_only(status::kNoState);
        m.last_status_ = status::kNoState;
        master_ = nullptr;
        session_ = false;
        if (then_start) {
            request(m, Op::Start);
        } else {
            start_waiting_master();
        }
        return;
    }
    case Op::None:
        return;
    }
}

void TwiBus::slave_released(Twi& slave) {
    if (master_ != nullptr && master_ != &slave) master_->sync();  // its next step is timed from its clock
    if (slave_ == &slave && !slave.addressed_) slave_ = nullptr;
    if (waiting_ != Op::None && !slave_holds_scl()) {
        const Op op = waiting_;
        waiting_ = Op::None;
        begin(op, waiting_then_start_);
    }
}

void TwiBus::start_waiting_master() {
    if (master_ != nullptr) return;
    for (Twi* t : members_) {
        if (t->start_pending_ && t->control_bit(kTwen)) {
            t->sync();
            t->start_pending_ = false;
            request(*t, Op::Start);
            return;
        }
    }
}

}  // namespace avrbench
