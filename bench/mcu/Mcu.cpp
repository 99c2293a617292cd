#include "mcu/Mcu.hpp"

#include <type_traits>
#include "mcu/SimavrStep.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <stdexcept>

extern "C" {
#include <avr_acomp.h>
#include <avr_extint.h>
#include <avr_ioport.h>
#include <sim_avr.h>
#include <sim_cycle_timers.h>
#include <sim_elf.h>
#include <sim_interrupts.h>
#include <sim_io.h>
}

#include "periph/adc/Adc.hpp"
#include "core/Errors.hpp"
#include "periph/ports/McuPins.hpp"
#include "mcu/DebugHook.hpp"
#include "mcu/IdleLoopSkip.hpp"
#include "mcu/IntelHex.hpp"
#include "mcu/TimingProfile.hpp"
#include "periph/watchdog/WatchdogWatch.hpp"
#include "periph/twi/Twi.hpp"
#include "core/UserStop.hpp"
#include "periph/timer/CompareOutputPins.hpp"
#include "periph/Fix.hpp"
#include "periph/interrupts/Interrupts.hpp"

namespace avrbench {

const FindingKind Mcu::kSimavrCrash = FindingKind::declare("simavr-crash", "simavr stopped the core (e.g. a write outside RAM)", Severity::Error);
const FindingKind Mcu::kInvalidOpcode = FindingKind::declare("invalid-opcode", "an opcode the AVR core does not decode", Severity::Error);
const FindingKind Mcu::kPcOutsideProgram = FindingKind::declare("pc-outside-program", "PC left the loaded program (erased flash or past flashend)", Severity::Error);
const FindingKind Mcu::kStackOverflow = FindingKind::declare("stack-overflow", "SP went below the end of .data/.bss/.noinit", Severity::Error);
const FindingKind Mcu::kBadInterrupt = FindingKind::declare("bad-interrupt", "an enabled interrupt without a handler reached __bad_interrupt", Severity::Error);
const FindingKind Mcu::kWatchdogReset = FindingKind::declare("watchdog-reset", "the watchdog timed out in system-reset mode", Severity::Error);
const FindingKind Mcu::kJumpToReset = FindingKind::declare("jump-to-reset", "execution reached the reset vector without a hardware reset", Severity::Error);

struct ResetHook {
    // avr_reset() zeroes the I/O space and then calls every module's reset;
    // the watchdog module sets MCUSR.WDRF in its own reset when the reset was
    // its doing. Wrapping that hook is how we see every reset and tell a
    // watchdog reset apart.
    static void watchdog_reset(avr_io_t* io) {
        avr_t* avr = io->avr;
        Mcu* mcu = AvrContext::find_in<Mcu>(avr, avr);
        mcu->original_watchdog_reset_(io);
        mcu->reset_seen_ = true;
        if (avr_regbit_get(avr, avr->reset_flags.wdrf)) mcu->watchdog_reset_seen_ = true;
    }
};

namespace {

std::string trim_line(const char* text) {
    std::string s;
    for (const char* p = text; *p != '\0'; ++p) {
        if (*p == '\x1b') {  // drop simavr's ANSI colour sequences
            while (*p != '\0' && *p != 'm') ++p;
            if (*p == '\0') break;
            continue;
        }
        if (*p == '\n' || *p == '\r') continue;
        s.push_back(*p);
    }
    return s;
}

}  // namespace

Mcu::Mcu(const ElfImage& elf, McuOptions options) : options_(std::move(options)), elf_(elf) {
    install_simavr_log_router();
    mcu_type_ = !options_.mcu_type.empty() ? options_.mcu_type : elf_.embedded_mcu();
    frequency_hz_ = options_.frequency_hz != 0 ? options_.frequency_hz : elf_.embedded_frequency_hz();
    // Both missing are named in one message, so one correction suffices.
    if (mcu_type_.empty() && frequency_hz_ == 0) {
        throw BadInput(elf_.path() + ": no MCU type and no clock frequency: the ELF has no .mmcu section; give both with "
                                     "--mcu and --freq (e.g. --mcu atmega328p --freq 16MHz) or run it on a board (--board)");
    }
    if (mcu_type_.empty()) {
        throw BadInput(elf_.path() + ": no MCU type: the ELF names none (no .mmcu section, or no MCU tag in it); give one with --mcu (e.g. --mcu atmega328p)");
    }
    if (frequency_hz_ == 0) {
        throw BadInput(elf_.path() + ": no clock frequency: the ELF gives none (no .mmcu section, or no frequency tag in it); give one with --freq (e.g. --freq 16MHz)");
    }
    avr_ = avr_make_mcu_by_name(mcu_type_.c_str());
    if (avr_ == nullptr) throw BadInput("unknown MCU '" + mcu_type_ + "' (simavr has no core by that name)");
    avr_init(avr_);
    cycle_ = &avr_->cycle;
    state_ = &avr_->state;
    AvrContext::attach(avr_, &context_);
    context_.add<Mcu>(avr_, this);
    route_simavr_log(avr_, this);
    avr_->log = LOG_ERROR;

    // A shallow copy: simavr only reads the firmware, and clearing tracecount
    // keeps simavr from opening its own VCD file for firmware that asks for one
    // (AVR_MMCU_TAG_VCD_TRACE); the bench's recorder is the one trace.
    elf_firmware_t firmware = elf_.simavr_firmware();
    firmware.tracecount = 0;
    if (firmware.flashbase + firmware.flashsize > avr_->flashend + 1) {
        // avr_loadcode() would abort() the whole process.
        const std::string message = elf_.path() + ": program of " + std::to_string(firmware.flashsize) +
                                    " bytes does not fit the " + std::to_string(avr_->flashend + 1) +
                                    "-byte flash of " + mcu_type_ + " (wrong --mcu?)";
        route_simavr_log(avr_, nullptr);
        avr_terminate(avr_);
        std::free(avr_);
        avr_ = nullptr;
        throw BadInput(message);
    }
    // An erased chip's lock byte (simavr leaves 0, every lock programmed);
    // avr_load_firmware copies the ELF's .lock over it.
    avr_->lockbits = 0xFF;
    avr_load_firmware(avr_, &firmware);
    avr_->frequency = frequency_hz_;
    if (options_.fuses) std::copy(options_.fuses->begin(), options_.fuses->end(), avr_->fuse);
    if (options_.lock_bits) avr_->lockbits = *options_.lock_bits;
    if (!options_.bootloader_hex.empty()) {
        try {
            load_bootloader();
        } catch (...) {
            route_simavr_log(avr_, nullptr);
            avr_terminate(avr_);
            std::free(avr_);
            avr_ = nullptr;
            throw;
        }
    }

    fixes_ = std::make_unique<SimavrFixes>(avr_);
    watchdog_watch_ = std::make_unique<WatchdogWatch>(avr_);
    scheduler_ = std::make_unique<Scheduler>(avr_);
    adc_ = std::make_unique<Adc>(avr_, mcu_type_);
    twi_ = Twi::install(avr_, mcu_type_, *scheduler_, options_.name);
    if (twi_) twi_->set_sync([this] { before_external_change(); });
    extint_ = reinterpret_cast<avr_extint_t*>(find_io_module(avr_, "extint"));
    acomp_ = reinterpret_cast<avr_acomp_t*>(find_io_module(avr_, "ac"));
    if (options_.skip_idle_loops && !options_.reference_run_loop) skipper_ = std::make_unique<IdleLoopSkipper>(avr_);

    for (avr_io_t* io = avr_->io_port; io != nullptr; io = io->next) {
        if (io->kind != nullptr && std::strcmp(io->kind, "watchdog") == 0 && io->reset != nullptr) {
            original_watchdog_reset_ = io->reset;
            io->reset = &ResetHook::watchdog_reset;
        }
    }

    elf_code_end_bytes_ = avr_->codeend;
    if (auto bad = elf_.symbol_address("__bad_interrupt")) elf_bad_interrupt_pc_ = *bad;
    if (elf_.ram_end_of_static_data() > 0) {
        // A push writes at SP and then decrements it, so SP = __bss_end - 1
        // is still clear of .bss; one lower and the last push overwrote it.
        elf_stack_floor_ = static_cast<std::uint16_t>(elf_.ram_end_of_static_data() - 1);
    }
    code_end_bytes_ = elf_code_end_bytes_;
    bad_interrupt_pc_ = elf_bad_interrupt_pc_;
    stack_floor_ = elf_stack_floor_;
    if (options_.predecoded_core && !options_.reference_run_loop) predecoded_ = make_predecoded_core();
}

std::unique_ptr<PredecodedCore> Mcu::make_predecoded_core() const {
    // The oracle limits run_until passes (code_end_bytes_ - 1 as there).
    return std::make_unique<PredecodedCore>(avr_, code_end_bytes_ - 1, bad_interrupt_pc_, options_.translate_blocks);
}

void Mcu::load_bootloader() {
    const std::string& hex = options_.bootloader_hex;
    if (!options_.fuses) {
        throw BadInput(hex + ": a boot loader needs the fuses that place it (e.g. fuses: {low: 0xFF, high: 0xDE, extended: 0xFD} on an UNO)");
    }
    boot_ = boot_section(mcu_type_, avr_->fuse);
    if (!boot_) throw BadInput(hex + ": the bench has no boot section table for " + mcu_type_ + " (periph/memory/BootSection.cpp)");
    char where[160];
    if (avr_->codeend > boot_->start_bytes) {
        std::snprintf(where, sizeof where, ": the application (%u bytes of flash) reaches into the boot section at 0x%05X",
                      static_cast<unsigned>(avr_->codeend), boot_->start_bytes);
        throw BadInput(elf_.path() + where);
    }
    const std::uint32_t flash_bytes = avr_->flashend + 1;
    for (const HexChunk& chunk : read_intel_hex(hex)) {
        const std::uint32_t end = chunk.address + static_cast<std::uint32_t>(chunk.bytes.size());
        if (chunk.address < boot_->start_bytes || end > flash_bytes) {
            std::snprintf(where, sizeof where,
                          ": bytes 0x%05X..0x%05X lie outside the boot section 0x%05X..0x%05X that BOOTSZ selects", chunk.address,
                          end - 1, boot_->start_bytes, flash_bytes - 1);
            throw BadInput(hex + where);
        }
        std::copy(chunk.bytes.begin(), chunk.bytes.end(), avr_->flash + chunk.address);
    }
    if (boot_->reset_into_boot) {
        avr_->reset_pc = boot_->start_bytes;
        avr_->pc = boot_->start_bytes;
    }
}

void Mcu::application_started() {
    ++application_starts_;
    // The boot loader may have written a new application: the ELF's oracles
    // hold while the flash still holds the ELF's bytes.
    const elf_firmware_t firmware = elf_.simavr_firmware();
    elf_matches_flash_ = firmware.flashbase + firmware.flashsize <= avr_->flashend + 1 &&
                         std::memcmp(avr_->flash + firmware.flashbase, firmware.flash, firmware.flashsize) == 0;
    code_end_bytes_ = elf_matches_flash_ ? elf_code_end_bytes_ : boot_->start_bytes;
    bad_interrupt_pc_ = elf_matches_flash_ ? elf_bad_interrupt_pc_ : ~0u;
    stack_floor_ = elf_matches_flash_ ? elf_stack_floor_ : 0;
}

std::string Mcu::describe_pc(std::uint32_t pc_bytes) const {
    if (elf_matches_flash_ && !in_boot_section(pc_bytes)) return elf_.describe_flash_address(pc_bytes);
    char text[32];
    std::snprintf(text, sizeof text, in_boot_section(pc_bytes) ? "boot loader+0x%x" : "0x%04x",
                  in_boot_section(pc_bytes) ? pc_bytes - boot_->start_bytes : pc_bytes);
    return text;
}

Mcu::~Mcu() {
    profiler_.reset();  // unhooks from the core's IRQs
    uarts_.clear();
    spi_.reset();
    pins_.clear();
    adc_.reset();
    twi_.reset();
    scheduler_.reset();
    watchdog_watch_.reset();  // its hook came after the fixes': undone first
    fixes_.reset();  // the fixes unhook themselves from the core: before it is freed
    predecoded_.reset();  // likewise (its flash watch is one of the core's I/O modules)
    if (avr_ != nullptr) {
        route_simavr_log(avr_, nullptr);
        avr_terminate(avr_);
        std::free(avr_);
    }
}

static_assert(cpu_Sleeping == 3, "Mcu::kCpuSleeping");
static_assert(std::is_same_v<avr_cycle_count_t, std::uint64_t>, "Mcu::cycle_");

bool Mcu::no_pending_interrupts() const { return !avr_has_pending_interrupts(avr_); }
Cycle Mcu::next_event_cycle() const {
    const avr_cycle_timer_slot_p head = avr_->cycle_timers.timer;
    return head == nullptr ? ~Cycle{0} : head->when;
}
void Mcu::set_debug_hook(DebugHook* hook) {
    if (hook != nullptr && debug_ == nullptr) skip_idle_before_debug_ = options_.skip_idle_loops;
    debug_ = hook;
    set_skip_idle_loops(hook == nullptr && skip_idle_before_debug_);
}

void Mcu::set_skip_idle_loops(bool on) {
    options_.skip_idle_loops = on;
    if (!on || options_.reference_run_loop) {
        skipper_.reset();
    } else if (!skipper_) {
        skipper_ = std::make_unique<IdleLoopSkipper>(avr_);
    }
}
void Mcu::set_predecoded_core(bool on) {
    if (in_run_) throw std::logic_error("Mcu::set_predecoded_core during a run");
    options_.predecoded_core = on;
    if (!on || options_.reference_run_loop) {
        predecoded_.reset();
    } else if (!predecoded_) {
        predecoded_ = make_predecoded_core();
    }
}
void Mcu::set_translate_blocks(bool on) {
    if (in_run_) throw std::logic_error("Mcu::set_translate_blocks during a run");
    if (options_.translate_blocks == on) return;
    options_.translate_blocks = on;
    if (predecoded_) predecoded_ = make_predecoded_core();
}
void Mcu::flash_written(std::uint32_t begin_bytes, std::uint32_t end_bytes) {
    if (predecoded_) predecoded_->flash_written(begin_bytes, end_bytes);
}
std::uint64_t Mcu::idle_jumps() const { return skipper_ ? skipper_->jumps() : 0; }
std::uint64_t Mcu::idle_cycles_skipped() const { return skipper_ ? skipper_->cycles_skipped() : 0; }
std::uint32_t Mcu::pc_bytes() const { return avr_->pc; }
std::uint16_t Mcu::stack_pointer() const {
    return static_cast<std::uint16_t>(avr_->data[R_SPL] | (avr_->data[R_SPH] << 8));
}
bool Mcu::sleeping() const { return avr_->state == cpu_Sleeping; }

Cycle Mcu::cycles_from_seconds(double seconds) const {
    return static_cast<Cycle>(std::llround(seconds * static_cast<double>(frequency_hz_)));
}

void Mcu::after_reset() {
    ++resets_;
    // avr_reset() drops every cycle timer: put the scheduler's back.
    scheduler_->rearm();
    if (twi_) twi_->reset();
    if (profiler_) profiler_->reset();
    watchdog_watch_->reset();
    for (auto& fn : reset_listeners_) fn();
}

std::vector<std::string> Mcu::requested_reset_lines() const {
    std::vector<std::string> out;
    for (const RequestedReset& r : requested_resets_) {
        char text[96];
        std::snprintf(text, sizeof text, "watchdog reset %s at %.6f s (", r.declared ? "expected by the board" : "asked for by the firmware",
                      static_cast<double>(r.cycle) / frequency_hz());
        out.push_back(text + std::string(r.declared ? "at " : "spinning at ") + describe_pc(r.pc_bytes) + ")");
    }
    return out;
}

int Mcu::on_pin_direction_change(std::function<void()> fn) {
    CompareOutputPins* overrides = CompareOutputPins::of(avr_);
    return overrides != nullptr ? overrides->on_direction_change(std::move(fn)) : -1;
}

void Mcu::remove_pin_direction_listener(int id) {
    if (CompareOutputPins* overrides = CompareOutputPins::of(avr_); overrides != nullptr && id >= 0) {
        overrides->remove_direction_listener(id);
    }
}

void Mcu::reset_external() {
    if (in_run_) throw std::logic_error("Mcu::reset_external during a run");
    if (halted_) {
        // A reset brings a halted core back (a SLEEP with interrupts off, a crash).
        halted_ = false;
        halt_reason_.clear();
    }
    avr_reset(avr_);
    reset_seen_ = false;
    watchdog_reset_seen_ = false;
    avr_regbit_set(avr_, avr_->reset_flags.extrf);
    after_reset();
}


std::uint8_t Mcu::peek(std::uint32_t data_address) const {
    if (data_address > avr_->ramend) throw BadInput("data address " + std::to_string(data_address) + " is past RAMEND");
    return avr_->data[data_address];
}

void Mcu::poke(std::uint32_t data_address, std::uint8_t value) {
    if (data_address > avr_->ramend) throw BadInput("data address " + std::to_string(data_address) + " is past RAMEND");
    avr_->data[data_address] = value;
}

std::vector<std::uint8_t> Mcu::data_memory() const { return {avr_->data, avr_->data + avr_->ramend + 1}; }

int Mcu::ioctl(std::uint32_t command, void* data) { return avr_ioctl(avr_, command, data); }

std::uint8_t Mcu::lockbits() const { return avr_->lockbits; }

std::size_t Mcu::cycle_timers_armed() const {
    std::size_t n = 0;
    for (auto* t = avr_->cycle_timers.timer; t != nullptr; t = t->next) ++n;
    return n;
}

bool Mcu::sleeps_in_virtual_time() const { return avr_->sleep != &avr_callback_sleep_raw; }

avr_io_t* Mcu::io_module(const char* kind, char name) const { return find_io_module(avr_, kind, name); }


std::uint16_t Mcu::pud_register() const { return part_facts(avr_).pud_register; }

void Mcu::add_finding(FindingKind kind, std::uint32_t pc_bytes, std::string detail, bool halt) {
    Finding f;
    f.kind = kind;
    f.source = options_.name;
    f.cycle = avr_->cycle;
    f.clock_hz = frequency_hz_;
    f.pc_bytes = pc_bytes;
    f.symbol = describe_pc(pc_bytes);
    f.detail = std::move(detail);
    findings_.record(std::move(f));
    if (halt) {
        halted_ = true;
        halt_reason_ = findings_.back().describe();
        request_stop();
    }
}

void Mcu::on_simavr_error(const char* message) {
    // avr_sadly_crashed() logs its own name after the message that explains
    // the crash; keep the explanation.
    if (std::strstr(message, "avr_sadly_crashed") == nullptr) last_error_log_ = trim_line(message);
    if (std::strstr(message, "Invalid Opcode") != nullptr && !halted_) {
        // _avr_invalid_opcode() logs before the PC moves: avr->pc is the opcode.
        const std::uint32_t pc = avr_->pc;
        const unsigned opcode = avr_->flash[pc] | (avr_->flash[pc + 1] << 8);
        char detail[64];
        std::snprintf(detail, sizeof detail, "opcode 0x%04x is not an AVR instruction", opcode);
        add_finding(kInvalidOpcode, pc, detail, true);
    }
}

bool Mcu::set_periodic_output_sink(Pin& pin, PeriodicOutputSink* sink) {
    CompareOutputPins* pins = CompareOutputPins::of(avr_);
    if (pins == nullptr) return false;
    pins->set_sink(pin.port(), __builtin_ctz(pin.mask()), sink);
    return true;
}

void Mcu::settle_periodic_outputs() {
    if (CompareOutputPins* pins = CompareOutputPins::of(avr_)) pins->stop_all_waves();
}

bool Mcu::pin_feeds_a_peripheral(const Pin& pin) const {
    const std::string& name = pin.name();  // "PB5"
    return !mcu_pinout_known(mcu_type_) || pin_may_feed_an_interrupt(mcu_type_, name[1], name[2] - '0');
}

bool Mcu::pin_interrupt_enabled(const Pin& pin) const {
    // The comparator can take any ADC pin through its multiplexer (ACME):
    // while its interrupt or its input capture trigger is on, every pin counts.
    if (acomp_ != nullptr) {
        if (acomp_->ac.enable.reg != 0 && avr_regbit_get(avr_, acomp_->ac.enable) != 0) return true;
        if (acomp_->acic.reg != 0 && avr_regbit_get(avr_, acomp_->acic) != 0) return true;
    }
    const char port = pin.name()[1];
    const auto bit = static_cast<std::uint8_t>(pin.name()[2] - '0');
    if (extint_ != nullptr) {
        for (const auto& line : extint_->eint) {
            if (line.port_ioctl == static_cast<std::uint32_t>(AVR_IOCTL_IOPORT_GETIRQ(port)) && line.port_pin == bit &&
                line.vector.enable.reg != 0 && avr_regbit_get(avr_, line.vector.enable) != 0) {
                return true;
            }
        }
    }
    const avr_ioport_t* io = pin.port();
    return io != nullptr && io->pcint.enable.reg != 0 && io->r_pcint != 0 &&
           avr_regbit_get(avr_, io->pcint.enable) != 0 && (avr_->data[io->r_pcint] & pin.mask()) != 0;
}

Pin& Mcu::pin(std::string_view name) {
    auto it = pins_.find(name);
    if (it != pins_.end()) return *it->second;
    std::string_view s = name;
    if (s.size() == 3 && (s[0] == 'P' || s[0] == 'p')) s.remove_prefix(1);
    const bool well_formed = s.size() == 2 && std::isalpha(static_cast<unsigned char>(s[0])) && s[1] >= '0' && s[1] <= '7';
    if (!well_formed) throw BadInput("bad pin name '" + std::string(name) + "' (expected e.g. PB5)");
    const char port = static_cast<char>(std::toupper(static_cast<unsigned char>(s[0])));
    const int bit = s[1] - '0';
    if (!mcu_has_pin(mcu_type_, port, bit)) {
        throw BadInput(mcu_type_ + " has no pin P" + std::string(1, port) + std::string(1, static_cast<char>('0' + bit)));
    }
    avr_irq_t* irq = avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(port), bit);
    if (irq == nullptr) throw BadInput(mcu_type_ + " has no port " + std::string(1, port) + " (pin '" + std::string(name) + "')");
    std::string canonical = std::string("P") + port + static_cast<char>('0' + bit);
    auto& slot = pins_[canonical];
    if (!slot) {
        auto* ioport = reinterpret_cast<avr_ioport_t*>(find_io_module(avr_, "port", port));
        slot = std::make_unique<Pin>(avr_, canonical, irq, ioport, bit);
    }
    return *slot;
}

Spi* Mcu::spi() {
    if (!spi_looked_for_) {
        spi_looked_for_ = true;
        std::function<bool()> miso_level;
        if (const auto pins = spi_pins(mcu_type_)) {
            Pin* miso = &pin(pins->miso);
            miso_level = [miso] { return miso->level(); };
        }
        spi_ = Spi::install(avr_, std::move(miso_level));
    }
    return spi_.get();
}

Uart& Mcu::uart(int index) {
    auto& slot = uarts_[index];
    if (!slot) {
        try {
            Pin* rx_pin = nullptr;
            if (const auto pins = usart_pins(mcu_type_, index)) {
                rx_pin = &pin(std::string("P") + pins->rx_port + static_cast<char>('0' + pins->rx_bit));
            }
            slot = std::make_unique<Uart>(avr_, *scheduler_, index, rx_pin);
        } catch (...) {
            uarts_.erase(index);
            throw;
        }
    }
    return *slot;
}

std::uint16_t Mcu::ram_address_of(const std::string& symbol) const {
    auto address = elf_.symbol_address(symbol);
    if (!address || *address < 0x800000) throw BadInput(elf_.path() + ": no RAM symbol '" + symbol + "'");
    return static_cast<std::uint16_t>(*address - 0x800000);
}

std::uint8_t Mcu::read_ram_u8(const std::string& symbol) const { return avr_->data[ram_address_of(symbol)]; }

std::vector<std::uint8_t> Mcu::read_ram(const std::string& symbol, std::size_t count) const {
    const std::uint16_t a = ram_address_of(symbol);
    if (a + count > static_cast<std::size_t>(avr_->ramend) + 1) {
        throw BadInput(elf_.path() + ": " + symbol + " + " + std::to_string(count) + " bytes is past the end of RAM");
    }
    return std::vector<std::uint8_t>(avr_->data + a, avr_->data + a + count);
}

std::uint16_t Mcu::read_ram_u16(const std::string& symbol) const {
    const std::uint16_t a = ram_address_of(symbol);
    return static_cast<std::uint16_t>(avr_->data[a] | (avr_->data[a + 1] << 8));
}

}  // namespace avrbench
