#include "parts/Tmc2130.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/Errors.hpp"
#include "mcu/Mcu.hpp"
#include "parts/PartRegistry.hpp"

namespace avrbench {

REGISTER_PART(Tmc2130, "tmc2130");

const FindingKind Tmc2130::kStepWhileOff = FindingKind::declare(
    "tmc-step-while-off", "STEP edges reached a TMC2130 whose outputs are off (ENN high, or CHOPCONF.toff = 0 as after power-up)",
    Severity::Warning);
const FindingKind Tmc2130::kWriteToReadOnly = FindingKind::declare(
    "tmc-write-to-read-only", "a write datagram to a TMC2130 register that is read-only", Severity::Warning);
const FindingKind Tmc2130::kUnknownRegister = FindingKind::declare(
    "tmc-unknown-register", "a datagram to an address the TMC2130 has no register at", Severity::Warning);
const FindingKind Tmc2130::kDatagramLength = FindingKind::declare(
    "tmc-datagram-length", "chip select rose before the 40 bits of a TMC2130 datagram were shifted", Severity::Warning);

namespace {

// Register bits (§5.1 GCONF, §5.5 CHOPCONF, COOLCONF, DRV_STATUS, §5.2 IHOLD_IRUN).
constexpr std::uint32_t kShaft = 1u << 4;
constexpr std::uint32_t kDiag0Stall = 1u << 7, kDiag1Stall = 1u << 8;
constexpr std::uint32_t kDiag0PushPull = 1u << 12, kDiag1PushPull = 1u << 13;
constexpr std::uint32_t kVsense = 1u << 17, kDedge = 1u << 29;
constexpr unsigned kMresShift = 24;

// §5 register map: what each address allows.
enum class Access { None, Read, Write, ReadWrite, ReadClear };
Access access_of(std::uint8_t a) {
    switch (a) {
        case Tmc2130::kGconf: case Tmc2130::kXdirect: case Tmc2130::kChopconf: return Access::ReadWrite;
        case Tmc2130::kGstat: return Access::ReadClear;
        case Tmc2130::kIoin: case Tmc2130::kTstep: case Tmc2130::kMscnt: case Tmc2130::kMscuract:
        case Tmc2130::kDrvStatus: case Tmc2130::kPwmScale: case Tmc2130::kLostSteps: return Access::Read;
        case Tmc2130::kIholdIrun: case Tmc2130::kTpowerdown: case Tmc2130::kTpwmthrs: case Tmc2130::kTcoolthrs:
        case Tmc2130::kThigh: case Tmc2130::kVdcmin: case Tmc2130::kCoolconf: case Tmc2130::kDcctrl:
        case Tmc2130::kPwmconf: case Tmc2130::kEncmCtrl: return Access::Write;
        default: return a >= Tmc2130::kMslut0 && a <= Tmc2130::kMslutstart ? Access::Write : Access::None;
    }
}

// 2^20 clocks without a step: standstill (DRV_STATUS.stst), TSTEP's overflow value.
constexpr double kStandstillClocks = 1048576.0;

// A stallGuard2 reading moves by this much per SGT step (assumed: the
// datasheet gives no figure; SGT spans -64..63 over SG_RESULT's 0..1023).
constexpr int kSgPerSgtStep = 16;

}  // namespace

std::vector<ParamSpec> Tmc2130::param_specs() {
    using PT = ParamType;
    return {
        {.name = "microsteps", .type = PT::Integer, .default_value = "16",
         .source = "the firmware's setting, as the axis' steps_per_mm counts it",
         .help = "the resolution an axis connected to `steps` counts its steps_per_mm in (MRES is the firmware's)",
         .min = 1, .max = 256},
        {.name = "forward_dir", .type = PT::Choice, .default_value = "high", .choices = {"high", "low"},
         .help = "DIR level counted as + (GCONF.shaft inverts it)"},
        {.name = "rsense", .type = PT::Quantity, .dimension = Dimension::Resistance, .default_value = "0.22ohm",
         .source = "assumed: the board's sense resistors (Einsy RAMBo, Prusa's TMC2130_RSENSE)",
         .help = "sense resistor; the current is (CS+1)/32 * V_FS / (R_SENSE + 20 mOhm) (datasheet §9)", .min = 0.01, .max = 10},
        {.name = "clock", .type = PT::Quantity, .dimension = Dimension::Frequency, .default_value = "12MHz",
         .source = "assumed: nominal internal oscillator (datasheet §4.3 gives SCK limits against it)",
         .help = "f_CLK: TSTEP's unit and standstill's 2^20 clocks", .min = 1e6, .max = 20e6},
        {.name = "motor_supply", .type = PT::Quantity, .dimension = Dimension::Voltage, .default_value = "24V",
         .source = "assumed: a 24 V printer supply (Einsy RAMBo)", .help = "VM, the most the chopper can put across a winding"},
        {.name = "sg_free", .type = PT::Integer, .default_value = "500",
         .source = "assumed: SG_RESULT of a motor turning freely at SGT 0 (datasheet §8: 0..1023, higher = less load)",
         .help = "stallGuard2 reading without load", .min = 0, .max = 1023},
        {.name = "stall_sgt", .type = PT::Integer, .default_value = "0",
         .source = "the motor's tuning: the SGT its maker found to read 0 with the motor blocked at homing speed "
                   "(Prusa MK3S: TMC2130_SG_THRS_X/Y 3, Z 4)",
         .help = "COOLCONF.SGT at which a blocked motor reads SG_RESULT 0; each SGT step away moves the reading by 16",
         .min = -64, .max = 63},
    };
}

Tmc2130::Tmc2130(std::string name, Mcu& clock, const ParamValues& params) : Part(std::move(name), clock) {
    step_pin_ = add_pin("step", TerminalRole::Input);
    dir_pin_ = add_pin("dir", TerminalRole::Input);
    enn_pin_ = add_pin("enn", TerminalRole::Input);
    cs_pin_ = add_pin("cs", TerminalRole::Input);
    sck_pin_ = add_pin("sck", TerminalRole::Input);
    mosi_pin_ = add_pin("mosi", TerminalRole::Input);
    // SDO: the bytes travel at byte level through the MCU's SPI
    // (periph/spi/Spi.hpp), so the pin only marks the bus; as an output it
    // would fight every other slave's on the shared MISO net.
    miso_pin_ = add_pin("miso", TerminalRole::Input);
    diag0_pin_ = add_pin("diag0", TerminalRole::Output);
    diag1_pin_ = add_pin("diag1", TerminalRole::Output);
    const long long microsteps = params.integer("microsteps");
    if ((microsteps & (microsteps - 1)) != 0) throw part_error(this->name(), "microsteps must be a power of two from 1 to 256");
    configured_microsteps_ = static_cast<unsigned>(microsteps);
    forward_dir_level_ = params.text("forward_dir") == "high";
    rsense_ohm_ = params.quantity("rsense");
    clock_hz_ = params.quantity("clock");
    motor_supply_v_ = params.quantity("motor_supply");
    sg_free_ = static_cast<int>(params.integer("sg_free"));
    stall_sgt_ = static_cast<int>(params.integer("stall_sgt"));

    sig_position_ = add_signal("position_steps", true);
    sig_enabled_ = add_signal("enabled", false, 0);
    sig_sg_ = add_signal("sg_result", true, 0);
    sig_stall_ = add_signal("stall", false, 0);
    provide_port<ShaftMotion>("steps", *this, "the shaft motion an axis follows");
    provide_port<DriveSource>("windings", *this, "a bipolar motor's two windings, as an ideal chopper");
    require_port<Carriage>("load", false, "the axis whose end of travel stalls the motor (stallGuard2)",
                           [this](Carriage& c) { load_ = &c; });
    add_readout("microsteps", [this] { return static_cast<double>(this->microsteps()); });
    add_readout("sg_result", [this] { return static_cast<double>(sg_result_); });
    add_readout("datagrams", [this] { return static_cast<double>(datagrams_); });
}

void Tmc2130::start() {
    if (connected(sck_pin_) || connected(mosi_pin_) || connected(miso_pin_)) {
        attach_spi_slave(*this, sck_pin_, mosi_pin_, miso_pin_, *this);
    }
    selected_ = connected(cs_pin_) && !input_level(cs_pin_);
    publish(sig_enabled_, driver_on() ? 1 : 0);
    drive_diag();
}

// ENN low enables the outputs (§3.3 pin table); unwired, taken as enabled.
bool Tmc2130::driver_on() const {
    const bool enn_low = !connected(enn_pin_) || !input_level(enn_pin_);
    return enn_low && (regs_[kChopconf] & 0x0F) != 0;
}

// MRES (CHOPCONF bits 27:24): 0 = 256 microsteps ... 8 = full steps; 9..15 are
// taken as full steps.
unsigned Tmc2130::microsteps() const {
    const unsigned mres = (regs_[kChopconf] >> kMresShift) & 0x0F;
    return 256u >> std::min(mres, 8u);
}

bool Tmc2130::standstill() const {
    if (!have_step_) return true;
    return static_cast<double>(clock().cycle() - last_step_cycle_) / clock().frequency_hz() * clock_hz_ >= kStandstillClocks;
}

// TSTEP: the time between two 1/256 microsteps in 1/f_CLK; 2^20 - 1 at standstill.
std::uint32_t Tmc2130::tstep() const {
    if (standstill() || last_step_period_cycles_ == 0) return 0xFFFFF;
    const double clocks = static_cast<double>(last_step_period_cycles_) / clock().frequency_hz() * clock_hz_ /
                          (256.0 / microsteps());
    return static_cast<std::uint32_t>(std::min(clocks, kStandstillClocks - 1));
}

std::uint32_t Tmc2130::read_register(std::uint8_t address) const {
    switch (address) {
        case kGstat: return reset_flag_ ? 1u : 0u;
        case kIoin: {
            // STEP bit 0, DIR bit 1, DRV_ENN_CFG6 bit 4, VERSION 0x11 in bits 31:24 (§5.1).
            std::uint32_t v = 0x11000000u;
            if (input_level(step_pin_)) v |= 1u;
            if (input_level(dir_pin_)) v |= 2u;
            if (connected(enn_pin_) && input_level(enn_pin_)) v |= 1u << 4;
            return v;
        }
        case kTstep: return tstep();
        case kMscnt: return static_cast<std::uint32_t>(((position_256_ % 1024) + 1024) % 1024);
        case kDrvStatus: {
            const std::uint32_t ihold_irun = regs_[kIholdIrun];
            const std::uint32_t cs = standstill() ? (ihold_irun & 0x1F) : ((ihold_irun >> 8) & 0x1F);
            std::uint32_t v = static_cast<std::uint32_t>(sg_result_) & 0x3FF;
            v |= cs << 16;
            if (stall_) v |= 1u << 24;
            if (standstill()) v |= 1u << 31;
            return v;
        }
        default: break;
    }
    const Access a = access_of(address);
    return a == Access::ReadWrite ? regs_[address] : 0;
}

void Tmc2130::write_register(std::uint8_t address, std::uint32_t value) {
    const Access a = access_of(address);
    char text[120];
    if (a == Access::None) {
        std::snprintf(text, sizeof text, "write of 0x%08X to address 0x%02X, which has no register (datasheet §5)", value, address);
        report(kUnknownRegister, text);
        return;
    }
    if (a == Access::Read || a == Access::ReadClear) {
        std::snprintf(text, sizeof text, "write of 0x%08X to read-only register 0x%02X (datasheet §5)", value, address);
        report(kWriteToReadOnly, text);
        return;
    }
    const bool was_on = driver_on();
    regs_[address] = value;
    if (driver_on() != was_on) {
        publish(sig_enabled_, driver_on() ? 1 : 0);
        off_reported_ = false;
        notify_drive_change();
    }
    drive_diag();
}

std::uint8_t Tmc2130::spi_status() const {
    // SPI_STATUS (§4.1.2): reset_flag, driver_error, sg2, standstill.
    std::uint8_t s = 0;
    if (reset_flag_) s |= 1u;
    if (stall_) s |= 1u << 2;
    if (standstill()) s |= 1u << 3;
    return s;
}

void Tmc2130::on_cs(bool level) {
    const bool selected = !level;
    if (selected == selected_) return;
    selected_ = selected;
    if (selected) {
        // The reply: the status now and the data the last datagram asked for.
        in_bits_ = (static_cast<std::uint64_t>(spi_status()) << 32) | reply_data_;
        bits_in_ = 0;
    } else {
        latch_datagram();
    }
}

void Tmc2130::latch_datagram() {
    if (bits_in_ == 0) return;
    if (bits_in_ < 40) {
        report(kDatagramLength, "chip select rose after " + std::to_string(bits_in_) +
                                    " bits; a datagram is 40 bits (datasheet §4.1), this one is ignored");
        return;
    }
    ++datagrams_;
    // More than 40 bits: a daisy chain; this chip keeps the last 40 (§4.1.3).
    const auto address = static_cast<std::uint8_t>((in_bits_ >> 32) & 0xFF);
    const auto data = static_cast<std::uint32_t>(in_bits_ & 0xFFFFFFFFu);
    if ((address & 0x80) != 0) {
        write_register(address & 0x7F, data);
        // The next datagram returns the data written (datasheet §4.1 example).
        reply_data_ = data;
        return;
    }
    if (access_of(address) == Access::None) {
        char text[80];
        std::snprintf(text, sizeof text, "read of address 0x%02X, which has no register (datasheet §5)", address);
        report(kUnknownRegister, text);
    }
    reply_data_ = read_register(address);
    if (address == kGstat) reset_flag_ = false;  // R+C: cleared by the read
}

std::optional<std::uint8_t> Tmc2130::exchange(const SpiTransfer& transfer) {
    if (!selected_) return std::nullopt;
    // Datasheet §4.3: SPI mode 3, MSB first, f_SCK at most 4 MHz on the internal clock.
    static const SpiLimits kLimits{3, false, 4e6, "TMC2130 datasheet §4.3: SPI mode 3, MSB first, f_SCK <= 4 MHz"};
    // Each once: every byte after it would say the same.
    if (!mode_reported_) {
        if (std::string why = spi_mode_problem(transfer, kLimits); !why.empty()) {
            mode_reported_ = true;
            report(kSpiModeMismatch, why);
        }
    }
    if (!clock_reported_) {
        if (std::string why = spi_clock_problem(transfer, kLimits); !why.empty()) {
            clock_reported_ = true;
            report(kSpiClockTooFast, why);
        }
    }
    // SDO shifts the register's top byte out while SDI shifts into its bottom.
    const auto out = static_cast<std::uint8_t>((in_bits_ >> 32) & 0xFF);
    in_bits_ = ((in_bits_ << 8) | transfer.mosi) & 0xFFFFFFFFFFull;
    bits_in_ += 8;
    return out;
}

void Tmc2130::on_input(std::size_t pin, bool level) {
    if (pin == cs_pin_) {
        on_cs(level);
    } else if (pin == step_pin_) {
        // dedge: both edges step (CHOPCONF bit 29); otherwise the rising one.
        if (level || (regs_[kChopconf] & kDedge) != 0) on_step_edge();
    } else if (pin == enn_pin_) {
        publish(sig_enabled_, driver_on() ? 1 : 0);
        off_reported_ = false;
        notify_drive_change();
    }
}

void Tmc2130::on_step_edge() {
    const Cycle now = clock().cycle();
    if (!driver_on()) {
        ++steps_while_off_;
        if (!off_reported_) {
            off_reported_ = true;
            const bool enn_high = connected(enn_pin_) && input_level(enn_pin_);
            report(kStepWhileOff, std::string("STEP edge while the outputs are off (") +
                                      (enn_high ? "ENN high" : "CHOPCONF.toff = 0: the driver is disabled, as after power-up") +
                                      "); the motor does not move");
        }
        return;
    }
    if (have_step_) {
        last_step_period_cycles_ = now - last_step_cycle_;
        if (last_step_period_cycles_ > 0) {
            peak_step_rate_hz_ = std::max(peak_step_rate_hz_, clock().frequency_hz() / static_cast<double>(last_step_period_cycles_));
        }
    }
    have_step_ = true;
    last_step_cycle_ = now;
    const bool forward = (input_level(dir_pin_) == forward_dir_level_) != ((regs_[kGconf] & kShaft) != 0);
    const int delta = static_cast<int>(256 / microsteps()) * (forward ? 1 : -1);
    const double before_mm = load_ != nullptr ? load_->position_mm() : 0;
    position_256_ += delta;
    ++steps_taken_;
    publish(sig_position_, static_cast<double>(position_256_) * configured_microsteps_ / 256.0);
    for (auto& fn : step_listeners_) fn(delta);
    update_stallguard(load_ != nullptr && load_->position_mm() == before_mm);
    note_activity();
    notify_drive_change();
}

// stallGuard2 (§8): SG_RESULT falls with the load, 0 at a stall; SGT
// (COOLCONF bits 22:16, signed) shifts it, a higher SGT needing more load for
// 0 (at the motor's tuned `stall_sgt`). The load here is all or nothing: a carriage that did not move on a
// step is blocked (its axis at an end of travel). A stall counts while
// stallGuard is active: THIGH <= TSTEP <= TCOOLTHRS (§8.2 TCOOLTHRS).
void Tmc2130::update_stallguard(bool blocked) {
    int sgt = static_cast<int>((regs_[kCoolconf] >> 16) & 0x7F);
    if (sgt >= 64) sgt -= 128;
    const int raw = (blocked ? 0 : sg_free_) + kSgPerSgtStep * (sgt - stall_sgt_);
    sg_result_ = std::clamp(raw, 0, 1023);
    const std::uint32_t t = tstep();
    const bool active = regs_[kTcoolthrs] != 0 && t <= regs_[kTcoolthrs] && t >= regs_[kThigh];
    const bool stall = active && sg_result_ == 0;
    publish(sig_sg_, sg_result_);
    if (stall != stall_) {
        stall_ = stall;
        publish(sig_stall_, stall ? 1 : 0);
        drive_diag();
    }
}

// DIAG0/DIAG1 (§5.1 GCONF): open drain, active low, unless *_pushpull makes
// them push-pull, active high; a stall drives them when diag*_stall routes it.
void Tmc2130::drive_diag() {
    const std::uint32_t g = regs_[kGconf];
    const auto set = [this](std::size_t pin, bool asserted, bool push_pull) {
        if (push_pull) {
            drive_output(pin, asserted);
        } else if (asserted) {
            drive_output(pin, false);
        } else {
            release_output(pin);
        }
    };
    set(diag0_pin_, stall_ && (g & kDiag0Stall) != 0, (g & kDiag0PushPull) != 0);
    set(diag1_pin_, stall_ && (g & kDiag1Stall) != 0, (g & kDiag1PushPull) != 0);
}

// §9 "Selecting sense resistors": I_RMS = (CS+1)/32 * V_FS/(R_SENSE+20 mOhm)
// / sqrt(2), V_FS 0.32 V (vsense 0) or 0.18 V (vsense 1): the peak is I_RMS * sqrt(2).
double Tmc2130::peak_current_a() const {
    const std::uint32_t ihold_irun = regs_[kIholdIrun];
    const unsigned cs = standstill() ? (ihold_irun & 0x1F) : ((ihold_irun >> 8) & 0x1F);
    const double vfs = (regs_[kChopconf] & kVsense) != 0 ? 0.18 : 0.32;
    return (cs + 1) / 32.0 * vfs / (rsense_ohm_ + 0.020);
}

// The default sine table starts with coil A at 0 and coil B at its peak
// (MSLUTSTART: START_SIN 0, START_SIN90 247): 90 electrical degrees ahead of
// the A4988's home state; a full step is 256 of position_256, 90 degrees.
double Tmc2130::commanded_electrical_angle() const {
    return 1.5707963267948966 + static_cast<double>(position_256_) * (1.5707963267948966 / 256);
}

WindingDrive Tmc2130::winding_at(const WindingTap& tap) const {
    WindingDrive d;
    if (driver_on()) {
        const double e = commanded_electrical_angle();
        d.current_mode = true;
        d.target_a = peak_current_a() * (tap.phase == 0 ? std::cos(e) : std::sin(e));
        d.supply_v = motor_supply_v_;
        d.polarity = 1;
    } else {
        // toff = 0 or ENN high: every bridge off, the windings float.
        d.v_pos = -(motor_supply_v_ + 1.4);
        d.v_neg = motor_supply_v_ + 1.4;
    }
    return d;
}

std::string Tmc2130::tap_problem(const WindingTap& tap) const {
    return tap.phase == 0 || tap.phase == 1 ? std::string{} : "a TMC2130 drives phases A and B only";
}

std::string Tmc2130::motion_summary() const {
    char text[120];
    std::snprintf(text, sizeof text, "%llu steps (%llu while off)", static_cast<unsigned long long>(steps_taken_),
                  static_cast<unsigned long long>(steps_while_off_));
    return text;
}

std::string Tmc2130::rate_summary() const {
    char text[60];
    std::snprintf(text, sizeof text, ", peak %.0f steps/s", peak_step_rate_hz_);
    return text;
}

std::string Tmc2130::summary() {
    char text[200];
    std::snprintf(text, sizeof text, "driver     %s: TMC2130 1/%u (MRES %u)%s, %s, %.2f A peak, %llu datagrams, SG_RESULT %d%s",
                  name().c_str(), microsteps(), (regs_[kChopconf] >> kMresShift) & 0x0F, (regs_[kChopconf] & kDedge) != 0 ? ", dedge" : "",
                  driver_on() ? "on" : "off", peak_current_a(), static_cast<unsigned long long>(datagrams_), sg_result_,
                  stall_ ? ", stalled" : "");
    return text;
}

void Tmc2130::on_bus_contention(const std::string& others, Cycle) {
    if (contention_reported_) return;
    contention_reported_ = true;
    report(kSpiBusContention, spi_contention_detail(others));
}

}  // namespace avrbench
