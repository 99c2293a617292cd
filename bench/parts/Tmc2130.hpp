// Trinamic TMC2130 stepper driver (TMC2130 datasheet Rev. 1.09, 2017-05-15):
// STEP/DIR/ENN and the SPI register file. The microstep resolution (MRES),
// double-edge stepping (dedge), the chopper's off time (toff, 0 = driver
// off), the motor direction (shaft), the run and hold currents
// (IHOLD_IRUN, vsense, the sense resistor) come from the registers the
// firmware writes; stallGuard2 reports a carriage that cannot move (its
// axis at an end of travel) as SG_RESULT 0 and a stall on DIAG0/DIAG1 as
// GCONF routes it. What is modelled and what is assumed: docs/BOARDS.md.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "parts/Carriage.hpp"
#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ShaftMotion.hpp"
#include "parts/SpiBus.hpp"
#include "parts/WindingDrive.hpp"

namespace avrbench {

class Tmc2130 final : public Part, public DriveSource, public ShaftMotion, public SpiSlave {
public:
    static const FindingKind kStepWhileOff;      // tmc-step-while-off
    static const FindingKind kWriteToReadOnly;   // tmc-write-to-read-only
    static const FindingKind kUnknownRegister;   // tmc-unknown-register
    static const FindingKind kDatagramLength;    // tmc-datagram-length
    static std::vector<ParamSpec> param_specs();

    Tmc2130(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "tmc2130"; }
    void start() override;
    std::string summary() override;

    // Register addresses (§5 "Register Map").
    enum Register : std::uint8_t {
        kGconf = 0x00, kGstat = 0x01, kIoin = 0x04, kIholdIrun = 0x10, kTpowerdown = 0x11, kTstep = 0x12,
        kTpwmthrs = 0x13, kTcoolthrs = 0x14, kThigh = 0x15, kXdirect = 0x2D, kVdcmin = 0x33, kMslut0 = 0x60,
        kMslutsel = 0x68, kMslutstart = 0x69, kMscnt = 0x6A, kMscuract = 0x6B, kChopconf = 0x6C, kCoolconf = 0x6D,
        kDcctrl = 0x6E, kDrvStatus = 0x6F, kPwmconf = 0x70, kPwmScale = 0x71, kEncmCtrl = 0x72, kLostSteps = 0x73,
    };
    // What a read of `address` returns now (0 for a write-only register).
    std::uint32_t read_register(std::uint8_t address) const;
    std::uint32_t written(std::uint8_t address) const { return regs_[address & 0x7F]; }
    unsigned microsteps() const;  // 256 >> MRES
    bool driver_on() const;       // ENN low and toff != 0
    int sg_result() const { return sg_result_; }
    bool stalled() const { return stall_; }
    std::uint64_t datagrams() const { return datagrams_; }

    // ShaftMotion.
    unsigned configured_microsteps() const override { return configured_microsteps_; }
    std::int64_t position_256() const override { return position_256_; }
    void on_step(std::function<void(int delta_256)> fn) override { step_listeners_.push_back(std::move(fn)); }
    std::uint64_t steps_taken() const override { return steps_taken_; }
    std::string motion_summary() const override;
    std::string rate_summary() const override;

    // DriveSource: an ideal chopper at the run (or, at standstill, hold) current.
    bool commands_angle() const override { return true; }
    double commanded_electrical_angle() const override;
    bool outputs_enabled() const override { return driver_on(); }
    WindingDrive winding_at(const WindingTap& tap) const override;
    std::string tap_problem(const WindingTap& tap) const override;
    // The winding current's peak now (A): (CS+1)/32 * V_FS / (R_SENSE + 20 mOhm) * sqrt(2)... see the source.
    double peak_current_a() const;

    // SpiSlave.
    std::optional<std::uint8_t> exchange(const SpiTransfer& transfer) override;
    const std::string& spi_name() const override { return name(); }
    void on_bus_contention(const std::string& others, Cycle cycle) override;

private:
    void on_input(std::size_t pin, bool level) override;
    void on_step_edge();
    void on_cs(bool level);
    void latch_datagram();
    void write_register(std::uint8_t address, std::uint32_t value);
    std::uint8_t spi_status() const;
    bool standstill() const;
    std::uint32_t tstep() const;
    void update_stallguard(bool blocked);
    void drive_diag();

    std::size_t step_pin_, dir_pin_, enn_pin_, cs_pin_, sck_pin_, mosi_pin_, miso_pin_, diag0_pin_, diag1_pin_;
    unsigned configured_microsteps_;
    bool forward_dir_level_;
    double rsense_ohm_, clock_hz_, motor_supply_v_;
    int sg_free_;
    int stall_sgt_;

    std::array<std::uint32_t, 128> regs_{};
    bool reset_flag_ = true;  // GSTAT.reset: set at power-up, cleared by reading GSTAT
    // The datagram shifting in (the last 40 bits) and the reply shifting out.
    std::uint64_t in_bits_ = 0, out_bits_ = 0;
    unsigned bits_in_ = 0;
    std::uint32_t reply_data_ = 0;  // the data the next datagram returns
    std::uint64_t datagrams_ = 0;
    bool selected_ = false;
    bool contention_reported_ = false;
    bool mode_reported_ = false, clock_reported_ = false;

    std::int64_t position_256_ = 0;
    std::uint64_t steps_taken_ = 0, steps_while_off_ = 0;
    bool off_reported_ = false;
    bool have_step_ = false;
    Cycle last_step_cycle_ = 0, last_step_period_cycles_ = 0;
    double peak_step_rate_hz_ = 0;
    std::vector<std::function<void(int)>> step_listeners_;
    Carriage* load_ = nullptr;
    int sg_result_ = 0;
    bool stall_ = false;
    std::size_t sig_position_, sig_enabled_, sig_sg_, sig_stall_;
};

}  // namespace avrbench
