#pragma once

// The bench's state for one simavr core, reached from simavr callbacks that
// carry no parameter of their own: a module's reset hook is handed only its
// avr_io_t, the logger and avr->sleep only the avr_t. simavr keeps a pointer
// for its user in avr->custom.data; the core's Mcu puts its AvrContext there,
// so each core finds its own fixes without a process-wide table.

#include <cstddef>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

namespace avrbench {

class SimavrLogSink;

class AvrContext {
public:
    // Attaches `context` to `avr` (nullptr detaches).
    static void attach(avr_t* avr, AvrContext* context) { avr->custom.data = context; }
    // The context attached to `avr`, or nullptr.
    static AvrContext* of(const avr_t* avr) { return static_cast<AvrContext*>(avr->custom.data); }

    // Where simavr's error messages for this core go (nullptr: nowhere).
    SimavrLogSink* log_sink = nullptr;

    // A value of kind `Kind` (the fix's class, or a tag) that simavr's
    // callbacks find by `key` (the avr_io_t or avr_t they are handed). Two
    // kinds may share a key: the kind is part of it.
    template <typename Kind, typename T = Kind>
    void add(const void* key, T* value) {
        remove<Kind>(key);
        entries_.push_back({kind_of<Kind>(), key, const_cast<void*>(static_cast<const void*>(value))});
    }
    template <typename Kind>
    void remove(const void* key) {
        std::erase_if(entries_, [&](const Entry& e) { return e.kind == kind_of<Kind>() && e.key == key; });
    }
    template <typename Kind, typename T = Kind>
    T* find(const void* key) const {
        for (const Entry& e : entries_) {
            if (e.kind == kind_of<Kind>() && e.key == key) return static_cast<T*>(e.value);
        }
        return nullptr;
    }
    // find() on the context of `avr`, nullptr when it has none.
    template <typename Kind, typename T = Kind>
    static T* find_in(const avr_t* avr, const void* key) {
        const AvrContext* context = of(avr);
        return context != nullptr ? context->find<Kind, T>(key) : nullptr;
    }

private:
    template <typename T>
    static const void* kind_of() {
        static const char kind = 0;
        return &kind;
    }
    struct Entry {
        const void* kind;
        const void* key;
        void* value;
    };
    std::vector<Entry> entries_;
};

}  // namespace avrbench
