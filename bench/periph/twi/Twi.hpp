// The 2-wire Serial Interface (TWI, I2C) of one MCU, replacing simavr's.
//
// simavr 1.6's avr_twi cannot connect two AVRs: the master's address message
// lacks the ADDR condition a slave matches on, the master decides ACK/NACK
// synchronously before any slave could answer, a STOP gives the slave status
// 0x60 instead of 0xA0, and slave transmit never completes
// (docs/FIDELITY.md). This model takes over TWCR, TWDR and TWSR and follows
// the datasheet's state tables (ATmega328P §22.7 Tables 22-2..22-5,
// ATmega2560 §24.7, ATmega32 §22.7): status codes, ACK from the receiver's
// TWEA, address match through TWAR/TWAMR, general call, and clock stretching
// (a slave holds SCL low while its TWINT is set, so the master's next bus
// operation waits for it). MCUs whose SDA and SCL pins share nets on a board
// share one TwiBus (boards/Board.cpp); an MCU on no bus talks to an empty one,
// where every address is NACKed.
//
// Timing from the master's bit rate (§22.5.2: SCL = F_CPU / (16 + 2 TWBR
// 4^TWPS)): a byte with its ACK takes 9 SCL periods; START, repeated START and
// STOP take one (the datasheet gives no figure for the status latency of
// these; one period covers the setup and hold times of §28.7).
// SDA and SCL on the pins (§22.3, Figures 22-3..22-6): the master of each
// operation draws it on its own SDA and SCL as an open-drain output (pulled
// low, or let go to the pull-ups), in quarters of an SCL period: START pulls
// SDA low while SCL is high, every bit sets SDA while SCL is low and raises
// SCL in the middle of the period, the ninth bit carries the receiver's ACK
// (low) or NACK, STOP lets SDA go while SCL is high. The slave's bits (its
// ACKs, the bytes it transmits) are drawn by the master too, which is what a
// logic analyser on the nets sees; on the MCUs' own pins the board's nets
// carry it to the others.
// Not modelled: arbitration between two masters (a second START waits for
// the bus to be free), PRTWI.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/Time.hpp"

struct avr_t;
struct avr_int_vector_t;

namespace avrbench {

class IoWriteHook;
class Scheduler;
class TwiBus;

// SDA and SCL as pin names ("PC4"), from each datasheet's pin description.
struct TwiPins {
    std::string sda;
    std::string scl;
};
// Empty names for an MCU type the bench does not know the TWI pins of.
TwiPins twi_pins(const std::string& mcu_type);

// One byte or condition on the bus, for traces and tests.
struct TwiEvent {
    enum class Kind : std::uint8_t { Start, RepeatedStart, Address, Data, Stop };
    Kind kind;
    Cycle cycle;           // the master's cycle when the event completed
    std::uint8_t byte;     // address byte (SLA+R/W) or data; 0 for conditions
    bool acked;            // the receiver pulled SDA low in the 9th bit
};

class Twi {
public:
    // nullptr when the bench does not know the MCU type's TWI. simavr has no
    // TWI for the ATmega32 at all; the bench registers its vector (19, §11).
    static std::unique_ptr<Twi> install(avr_t* avr, const std::string& mcu_type, Scheduler& scheduler,
                                        std::string owner_name);
    ~Twi();
    Twi(const Twi&) = delete;
    Twi& operator=(const Twi&) = delete;

    const std::string& owner_name() const { return owner_name_; }
    // Moves this module onto `bus` (from the private one it starts on).
    void attach(TwiBus& bus);
    TwiBus& bus() { return *bus_; }
    // Calls `fn` for every bus event this MCU makes as master (nothing is
    // kept here: a long run's traffic would grow without bound).
    void on_event(std::function<void(const TwiEvent&)> fn) { listeners_.push_back(std::move(fn)); }

    // Called by Mcu after a reset: registers to their reset values, the bus let go.
    void reset();
    // Called before the bus changes what this module's MCU sees, while
    // another MCU runs (Mcu::before_external_change: the lockstep).
    void set_sync(std::function<void()> fn) { sync_ = std::move(fn); }
    void sync() {
        if (sync_) sync_();
    }

private:
    friend class TwiBus;
    // Data-space addresses (0 = the part has no such register).
    struct Registers {
        std::uint16_t twbr, twsr, twar, twdr, twcr, twamr;
    };
    Twi(avr_t* avr, Registers registers, avr_int_vector_t* vector, bool own_vector, Scheduler& scheduler,
        std::string owner_name, TwiPins pins);

    static void on_control_write(IoWriteHook& hook, avr_t* avr, std::uint16_t addr, std::uint8_t value);
    static void on_data_write(IoWriteHook& hook, avr_t* avr, std::uint16_t addr, std::uint8_t value);
    static void on_status_write(IoWriteHook& hook, avr_t* avr, std::uint16_t addr, std::uint8_t value);

    // Register bits and fields.
    bool control_bit(std::uint8_t mask) const;
    void set_control_bit(std::uint8_t mask, bool on);
    bool interrupt_flag() const;
    std::uint8_t status() const;
    std::uint8_t data() const;
    void set_data(std::uint8_t value);
    std::uint8_t own_address_register() const;
    std::uint8_t address_mask_register() const;
    // TWINT set with `status`: the firmware's turn (raises TWI_vect when TWIE).
    void post_status(std::uint8_t status);
    void set_status_only(std::uint8_t status);
    void clear_interrupt_flag();
    Cycle scl_period_cycles() const;

    // The firmware cleared TWINT (or started from idle): act on TWSTA/TWSTO/TWDR.
    void act();
    void disable();

    // The master's drawing of SDA and SCL: pull `line` low or let it go at
    // cycle `at` (open drain; nothing when the pins are unknown).
    enum Line : std::uint8_t { kSda = 0, kScl = 1 };
    void draw(Line line, bool low, Cycle at);
    void release_lines();

    avr_t* avr_;
    Registers registers_;
    avr_int_vector_t* vector_;
    bool own_vector_;  // registered by the bench (ATmega32): unregistered in the destructor
    Scheduler& scheduler_;
    std::string owner_name_;
    std::unique_ptr<IoWriteHook> control_hook_;
    std::unique_ptr<IoWriteHook> data_hook_;
    std::unique_ptr<IoWriteHook> status_hook_;
    std::unique_ptr<TwiBus> own_bus_;
    TwiBus* bus_ = nullptr;
    std::vector<std::function<void(const TwiEvent&)>> listeners_;
    void emit(const TwiEvent& event) const {
        for (const auto& fn : listeners_) fn(event);
    }

    // Slave side: the bus addressed this module (as receiver or transmitter).
    bool addressed_ = false;
    bool transmitting_ = false;   // slave transmitter (SLA+R)
    bool general_call_ = false;
    bool last_byte_ = false;      // slave transmitter loaded TWDR with TWEA = 0
    bool start_pending_ = false;  // TWSTA while the bus belongs to another master
    std::function<void()> sync_;
    std::uint8_t last_status_ = 0xF8;  // TWSR's status as the firmware last saw it with TWINT

    TwiPins pins_;
    int line_driver_[2] = {-2, -2};       // forced-output drivers of SDA, SCL; -2 not asked yet, -1 none
    bool line_low_[2] = {false, false};   // as last drawn (scheduled)
};

// The wires SDA and SCL between TWI modules: who owns the bus, who is
// addressed, and the master operation waiting for a stretching slave.
class TwiBus {
public:
    TwiBus() = default;
    ~TwiBus();
    TwiBus(const TwiBus&) = delete;
    TwiBus& operator=(const TwiBus&) = delete;
    void add(Twi& twi);
    void remove(Twi& twi);
    const std::vector<Twi*>& members() const { return members_; }
    const Twi* master() const { return master_; }

private:
    friend class Twi;
    enum class Op : std::uint8_t { None, Start, Address, Write, Read, Stop };

    // A master operation; begins now or once the addressed slave releases SCL.
    void request(Twi& master, Op op, bool then_start = false);
    void begin(Op op, bool then_start);
    // Draws the operation on the master's SDA and SCL pins as it begins.
    void draw(Op op);
    void complete(Op op, bool then_start);
    // The addressed slave cleared TWINT: SCL is free again.
    void slave_released(Twi& slave);
    void drop(Twi& twi);
    void start_waiting_master();
    Twi* find_slave(std::uint8_t address_byte, bool& general_call) const;
    bool slave_holds_scl() const;

    std::vector<Twi*> members_;
    Twi* master_ = nullptr;
    Twi* slave_ = nullptr;
    Op waiting_ = Op::None;
    bool waiting_then_start_ = false;
    bool in_flight_ = false;
    bool session_ = false;  // between the master's START and its STOP: a START now is a repeated one
    std::uint64_t generation_ = 0;  // completions of an aborted operation are ignored
};

}  // namespace avrbench
