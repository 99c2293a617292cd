#include "core/SerialLink.hpp"

namespace avrbench {

std::string SerialLink::transmitted_text() const {
    std::string out;
    out.reserve(transmitted().size());
    for (const auto& b : transmitted()) out.push_back(static_cast<char>(b.value));
    return out;
}

}  // namespace avrbench
