#include "core/VectorNames.hpp"

#include <cstring>

namespace avrbench {
namespace {

struct Entry {
    const char* mcu;
    int vector;
    const char* name;
};

// {"atmega328p", 11, "TIMER1_COMPA"}, ...: generated; where avr-libc keeps
// an old name beside the current one, a vector has both (either resolves,
// the first listed is shown).
const Entry kEntries[] = {
#include "core/VectorNames.inc"
    {"", 0, ""},
};

}  // namespace

std::string vector_name(const std::string& mcu_type, int vector) {
    for (const Entry& e : kEntries) {
        if (e.vector == vector && mcu_type == e.mcu) return e.name;
    }
    return "";
}

std::optional<int> vector_number(const std::string& mcu_type, const std::string& name) {
    std::string bare = name;
    if (bare.size() > 5 && bare.compare(bare.size() - 5, 5, "_vect") == 0) bare.resize(bare.size() - 5);
    for (const Entry& e : kEntries) {
        if (mcu_type == e.mcu && bare == e.name) return e.vector;
    }
    return std::nullopt;
}

std::optional<int> vector_count(const std::string& mcu_type) {
    std::optional<int> last;
    for (const Entry& e : kEntries) {
        if (mcu_type == e.mcu && (!last || e.vector > *last)) last = e.vector;
    }
    if (!last) return std::nullopt;
    return *last + 1;
}

}  // namespace avrbench
