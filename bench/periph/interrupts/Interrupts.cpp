#include "periph/interrupts/Interrupts.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstring>
#include <mutex>
#include <string_view>
#include <vector>

namespace avrbench {

PartFacts part_facts(const avr_t* avr) {
    PartFacts f;
    f.response_cycles = avr->address_size + 2;  // 2-byte PC: 4, 3-byte PC: 5
    const std::string_view mmcu = avr->mmcu != nullptr ? avr->mmcu : "";
    // The older megas: MCUCR holds the sleep bits, PINx is read-only, SBI/CBI
    // rewrite the whole register, INT2 is the only asynchronous line.
    for (std::string_view old : {"atmega8", "atmega16", "atmega32", "atmega64", "atmega128", "atmega162",
                                 "atmega8515", "atmega8535"}) {
        if (mmcu == old) {
            f.sleep_register = 0x55;  // MCUCR
            f.se_mask = 0x80;
            f.sm_shift = 4;
            f.pin_write_toggles = false;
            f.sbi_single_bit = false;
            f.synchronous_int_mask = 0x03;
            f.eeprom_write_us[0] = f.eeprom_write_us[1] = f.eeprom_write_us[2] = 8448;
            f.old_mega = true;
            f.pud_register = 0x50;  // SFIOR
            f.pud_mask = 0x04;
            f.known = true;
            return f;
        }
    }
    if (mmcu.starts_with("atmega") || mmcu.starts_with("attiny")) {
        f.sleep_register = 0x53;  // SMCR
        f.se_mask = 0x01;
        f.sm_shift = 1;
        // ATmega640/1280/1281/2560/2561: INT3:0 asynchronous, INT7:4 need clk_IO.
        const bool mega_2560_family = mmcu == "atmega640" || mmcu == "atmega1280" || mmcu == "atmega1281" ||
                                      mmcu == "atmega2560" || mmcu == "atmega2561";
        f.synchronous_int_mask = mega_2560_family ? 0xF0 : 0x03;
        f.known = mmcu.starts_with("atmega");
        if (f.known) {
            f.pud_register = 0x55;  // MCUCR
            f.pud_mask = 0x10;
        }
    }
    return f;
}

std::uint8_t sleep_mode(const avr_t* avr, const PartFacts& facts) {
    if (facts.sleep_register == 0) return kSleepIdle;
    return static_cast<std::uint8_t>((avr->data[facts.sleep_register] >> facts.sm_shift) & 0x7);
}

namespace {

// Start-up time from Power-down/Power-save for the clock source the low fuse
// selects (ATmega328P §9.2..9.6 Tables 9-4, 9-6, 9-8, 9-10, 9-12; the 2560's
// and the ATmega32's tables give the same values for these sources).
std::uint32_t startup_from_low_fuse(std::uint8_t low) {
    const unsigned cksel = low & 0x0F;
    const unsigned sut = (low >> 4) & 0x3;
    if (cksel == 0x0 || cksel == 0x2 || cksel == 0x3 || cksel == 0x1) return 6;  // external clock, RC oscillators
    if (cksel == 0x4 || cksel == 0x5) return sut == 2 ? 32768 : 1024;       // low-frequency crystal
    // Full-swing and low-power crystal oscillators (CKSEL 0110..1111).
    const bool cksel0 = (cksel & 1) != 0;
    if (!cksel0) return sut < 2 ? 258 : 1024;
    return sut == 0 ? 1024 : 16384;
}

}  // namespace

std::uint32_t wakeup_startup_cycles(const avr_t* avr, std::uint8_t mode) {
    switch (mode) {
        case kSleepPowerDown:
        case kSleepPowerSave: {
            bool has_fuses = false;
            for (std::uint8_t f : avr->fuse) has_fuses = has_fuses || f != 0;
            // Assumed without a .fuse section: Arduino UNO / Mega 2560 low fuse 0xFF
            // (low-power crystal, CKSEL = 1111, SUT = 11): 16K CK.
            return startup_from_low_fuse(has_fuses ? avr->fuse[0] : 0xFF);
        }
        case kSleepStandby:
        case kSleepExtendedStandby:
            return 6;  // §10.7: "the device wakes up in six clock cycles"
        default:
            return 0;
    }
}

bool sleep_was_a_nop(const avr_t* avr) {
    const PartFacts f = part_facts(avr);
    return f.sleep_register != 0 && (avr->data[f.sleep_register] & f.se_mask) == 0;
}

avr_int_vector_t* find_vector(avr_t* avr, int number) {
    for (int i = 0; i < avr->interrupts.vector_count; ++i) {
        if (avr->interrupts.vector[i]->vector == number) return avr->interrupts.vector[i];
    }
    return nullptr;
}

void unpend_interrupt(avr_t* avr, avr_int_vector_t* vector) {
    auto& fifo = avr->interrupts.pending;
    constexpr unsigned kSize = avr_int_pending_fifo_size;
    avr_int_vector_p kept[kSize];
    unsigned n = 0;
    for (unsigned i = fifo.read; i != fifo.write; i = (i + 1) & (kSize - 1)) {
        if (fifo.buffer[i] != vector) kept[n++] = fifo.buffer[i];
    }
    for (unsigned i = 0; i < n; ++i) fifo.buffer[i] = kept[i];
    fifo.read = 0;
    fifo.write = static_cast<decltype(fifo.write)>(n);
    vector->pending = 0;
    // simavr's service routine reads the FIFO whenever interrupt_state > 0,
    // even when it is empty.
    if (n == 0 && avr->interrupt_state > 0) avr->interrupt_state = 0;
}

void sync_enables(avr_t* avr, avr_io_addr_t reg) {
    for (int i = 0; i < avr->interrupts.vector_count; ++i) {
        avr_int_vector_t* v = avr->interrupts.vector[i];
        if (v->enable.reg != reg) continue;
        const bool enabled = avr_regbit_get(avr, v->enable) != 0;
        const bool flagged = v->raised.reg != 0 && avr_regbit_get(avr, v->raised) != 0;
        if (enabled && flagged && !v->pending) {
            avr_raise_interrupt(avr, v);
        } else if (!enabled && v->pending) {
            unpend_interrupt(avr, v);
        }
    }
}

std::uint8_t single_bit_write_value(const avr_t* avr, avr_io_addr_t addr, std::uint8_t value) {
    if (addr < 0x20 || addr > 0x3F) return value;  // SBI/CBI reach I/O 0x00..0x1F only
    const unsigned op = opcode_at(avr, avr->pc);
    const unsigned io = (op >> 3) & 0x1F;
    if (io != static_cast<unsigned>(addr - 0x20)) return value;
    if ((op & 0xFF00) == 0x9A00) return static_cast<std::uint8_t>(1u << (op & 7));  // SBI
    if ((op & 0xFF00) == 0x9800) return 0;                                          // CBI
    return value;
}

namespace {

struct SleepListener {
    avr_t* avr;
    SleepEntryListener fn;
    void* context;
};
std::mutex sleep_listeners_mutex;
std::vector<SleepListener>& sleep_listeners() {
    static std::vector<SleepListener> v;
    return v;
}
// Bumped on every change of the list (under the mutex): a thread's copy of
// one MCU's listeners stays good while it is unchanged.
std::atomic<std::uint64_t> sleep_listeners_generation{1};

}  // namespace

void add_sleep_entry_listener(avr_t* avr, SleepEntryListener fn, void* context) {
    std::lock_guard<std::mutex> lock(sleep_listeners_mutex);
    sleep_listeners().push_back({avr, fn, context});
    sleep_listeners_generation.fetch_add(1, std::memory_order_release);
}

void remove_sleep_entry_listener(avr_t* avr, void* context) {
    std::lock_guard<std::mutex> lock(sleep_listeners_mutex);
    auto& v = sleep_listeners();
    v.erase(std::remove_if(v.begin(), v.end(), [&](const SleepListener& l) { return l.avr == avr && l.context == context; }),
            v.end());
    sleep_listeners_generation.fetch_add(1, std::memory_order_release);
}

avr_cycle_count_t notify_sleep_entry(avr_t* avr, std::uint8_t mode) {
    // This MCU's listeners, copied out under the lock once per change of the
    // list and kept per thread (a core sleeps ~10^5 times a simulated
    // second on the five-MCU board: no lock, no scan of the other MCUs'
    // listeners per sleep).
    thread_local const avr_t* cached_avr = nullptr;
    thread_local std::uint64_t cached_generation = 0;
    thread_local std::vector<SleepListener> mine;
    const std::uint64_t generation = sleep_listeners_generation.load(std::memory_order_acquire);
    if (avr != cached_avr || generation != cached_generation) {
        std::lock_guard<std::mutex> lock(sleep_listeners_mutex);
        mine.clear();
        for (const auto& l : sleep_listeners()) {
            if (l.avr == avr) mine.push_back(l);
        }
        cached_avr = avr;
        cached_generation = sleep_listeners_generation.load(std::memory_order_relaxed);
    }
    avr_cycle_count_t earliest = 0;
    const auto call = [&](const SleepListener& l) {
        const avr_cycle_count_t at = l.fn(l.context, avr, mode);
        if (at != 0 && (earliest == 0 || at < earliest)) earliest = at;
    };
    // The calls run on a copy on the stack: a listener may add or remove one,
    // or make another MCU sleep (which refills `mine`). An MCU has a handful.
    constexpr std::size_t kInPlace = 8;
    if (mine.size() > kInPlace) {
        const std::vector<SleepListener> calling = mine;  // never in our boards
        for (const auto& l : calling) call(l);
        return earliest;
    }
    std::array<SleepListener, kInPlace> calling;
    const std::size_t count = mine.size();
    std::copy(mine.begin(), mine.end(), calling.begin());
    for (std::size_t i = 0; i < count; ++i) call(calling[i]);
    return earliest;
}

}  // namespace avrbench
