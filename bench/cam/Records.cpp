#include "cam/Records.hpp"

#include "core/GcodeLexer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "core/Errors.hpp"

namespace avrbench {
namespace {

// START byte bits (PORTB): PB0 X DIR, PB2 X EN (1 = off), PB4 Y EN, PB5 Y DIR.
constexpr std::uint8_t kXNeg = 0x01, kXOff = 0x04, kYOff = 0x10, kYNeg = 0x20;

struct Converter {
    const RecordOptions& o;
    RecordProgram out;
    long x = 0, y = 0;  // microsteps from home

    long steps(double mm) const { return std::lround(mm * o.steps_per_mm); }
    static double d(long v) { return static_cast<double>(v); }
    double mm(long v) const { return static_cast<double>(v) / o.steps_per_mm; }

    // OCR for `steps_per_s` microsteps/s: f / (2 N sps) - 1, truncated (thesis) or rounded.
    std::uint8_t ocr(double steps_per_s) const {
        if (!(steps_per_s > 0)) return 255;
        const double exact = o.cpu_hz / (2.0 * o.prescaler * steps_per_s) - 1.0;
        const double v = o.improved ? std::round(exact) : std::floor(exact);
        return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
    }
    // Seconds for `steps` at compare value `ocr`: two matches per step.
    double seconds(long steps, std::uint8_t ocr_value) const {
        return d(steps) * 2.0 * o.prescaler * (ocr_value + 1.0) / o.cpu_hz;
    }
    void add(std::string message, double busy_s) {
        out.messages.push_back(std::move(message));
        out.busy_seconds.push_back(busy_s);
    }
    static std::uint8_t start(long dx, long dy) {
        return static_cast<std::uint8_t>((dx == 0 ? kXOff : 0) | (dx < 0 ? kXNeg : 0) | (dy == 0 ? kYOff : 0) |
                                          (dy < 0 ? kYNeg : 0));
    }
    void count(std::string& m, long v) const {
        const int bytes = o.improved ? 3 : 2;
        for (int i = 0; i < bytes; ++i) m.push_back(static_cast<char>((static_cast<unsigned long>(v) >> (8 * i)) & 0xFF));
    }

    void rapid(long tx, long ty) {
        const long dx = tx - x, dy = ty - y;
        if (dx == 0 && dy == 0) return;
        const std::uint8_t r = ocr(o.rapid_mm_per_s * o.steps_per_mm);
        std::string m(1, '\x00');
        count(m, std::labs(dx));
        count(m, std::labs(dy));
        m += {static_cast<char>(r), static_cast<char>(r), static_cast<char>(start(dx, dy))};
        add(m, std::max(seconds(std::labs(dx), r), seconds(std::labs(dy), r)));
        ++out.moves;
        x = tx;
        y = ty;
    }

    void line(long tx, long ty, double feed_mm_s) {
        long dx = tx - x, dy = ty - y;
        if (dx == 0 && dy == 0) return;
        const double t = std::hypot(static_cast<double>(dx), static_cast<double>(dy)) / o.steps_per_mm / feed_mm_s;
        std::uint8_t ocr_x = ocr(d(std::labs(dx)) / t), ocr_y = ocr(d(std::labs(dy)) / t);
        long stepx = std::labs(dx);
        if (dx == 0 && !o.improved) {
            // The thesis: X's timer clocks the move, its driver off.
            stepx = std::labs(dy);
            ocr_x = ocr_y;
        }
        std::string m(1, '\x01');
        count(m, stepx);
        if (o.improved) count(m, std::labs(dy));
        m += {static_cast<char>(ocr_x), static_cast<char>(ocr_y), static_cast<char>(start(dx, dy))};
        add(m, std::max(seconds(stepx, ocr_x), o.improved ? seconds(std::labs(dy), ocr_y) : 0.0));
        ++out.moves;
        x = tx;
        y = ty;
    }

    void arc(bool clockwise, double ex, double ey, double ci, double cj, double feed_mm_s) {
        const double sx = mm(x), sy = mm(y);
        const double cx = sx + ci, cy = sy + cj;
        const double r = std::hypot(ci, cj);
        double a0 = std::atan2(sy - cy, sx - cx), a1 = std::atan2(ey - cy, ex - cx);
        double sweep = clockwise ? a0 - a1 : a1 - a0;  // positive, in the arc's direction
        while (sweep <= 1e-9) sweep += 2 * std::numbers::pi;        // a full circle when start == end
        // Chords no longer than chord_deg, and short enough for 8-bit counts.
        const double max_chord_mm = 255.0 / o.steps_per_mm;
        const double by_length = 2.0 * std::asin(std::min(1.0, max_chord_mm / (2.0 * std::max(r, 1e-9))));
        const double step = std::min(o.chord_deg * std::numbers::pi / 180.0, by_length);
        const int n = std::max(1, static_cast<int>(std::ceil(sweep / step - 1e-9)));
        std::string first(1, clockwise ? '\x02' : '\x03');
        bool head = true;
        for (int i = 1; i <= n; ++i) {
            const double a = a0 + (clockwise ? -1.0 : 1.0) * sweep * i / n;
            const long tx = i == n ? steps(ex) : steps(cx + r * std::cos(a));
            const long ty = i == n ? steps(ey) : steps(cy + r * std::sin(a));
            const long dx = tx - x, dy = ty - y;
            if (dx == 0 && dy == 0) continue;
            const double t = std::hypot(static_cast<double>(dx), static_cast<double>(dy)) / o.steps_per_mm / feed_mm_s;
            std::string m = head ? first : std::string();
            head = false;
            m.push_back(static_cast<char>(std::labs(dx)));
            if (o.improved) m.push_back(static_cast<char>(std::labs(dy)));
            m += {static_cast<char>(ocr(d(std::labs(dx)) / t)), static_cast<char>(ocr(d(std::labs(dy)) / t)),
                  static_cast<char>(start(dx, dy))};
            add(m, 0);
            ++out.chords;
            x = tx;
            y = ty;
        }
        // The closing record: both drivers off.
        std::string end = head ? first : std::string();
        end.push_back('\0');
        if (o.improved) end.push_back('\0');
        end += {'\0', '\0', static_cast<char>(kXOff | kYOff)};
        add(end, 0);
        ++out.arcs;
    }
};

}  // namespace

RecordProgram records_from_gcode(const std::string& gcode, const RecordOptions& options, const std::string& where) {
    Converter c{options, {}};
    std::istringstream in(gcode);
    std::string line;
    int number = 0;
    double feed_mm_s = 10;
    while (std::getline(in, line)) {
        ++number;
        const std::string at = where + ":" + std::to_string(number) + ": ";
        const auto words = lex_strict_gcode(line);
        if (!words) throw BadInput(at + "'" + line + "' is not G-code words (a capital letter and a number each)");
        int g = -1;
        bool m30 = false;
        double X = c.mm(c.x), Y = c.mm(c.y), I = 0, J = 0;
        for (const GcodeWord& w : *words) {
            const double v = w.value;
            const std::string word = line.substr(w.begin, w.end - w.begin);
            if (!std::isfinite(v)) throw BadInput(at + "'" + word + "' is not a finite number");
            switch (w.letter) {
                case 'G':
                    if (v == 21 || v == 90) break;
                    if (v != 0 && v != 1 && v != 2 && v != 3) throw BadInput(at + "G" + word.substr(1) + " is not G00..G03");
                    g = static_cast<int>(v);
                    break;
                case 'M':
                    if (v != 30) throw BadInput(at + "only M30 is understood");
                    m30 = true;
                    break;
                case 'X': X = v; break;
                case 'Y': Y = v; break;
                case 'I': I = v; break;
                case 'J': J = v; break;
                case 'F':
                    if (!(v > 0)) throw BadInput(at + "F must be above 0");
                    feed_mm_s = v / 60.0;
                    break;
                default: throw BadInput(at + "'" + word + "' is not understood");
            }
        }
        if (m30) {
            c.add(std::string(1, '\x3B'), 0);
            break;
        }
        if (X < 0 || Y < 0 || X > 1e4 || Y > 1e4) throw BadInput(at + "the target lies outside the machine (negative or beyond 10 m)");
        switch (g) {
            case 0: c.rapid(c.steps(X), c.steps(Y)); break;
            case 1: c.line(c.steps(X), c.steps(Y), feed_mm_s); break;
            case 2:
            case 3: c.arc(g == 2, X, Y, I, J, feed_mm_s); break;
            default: break;
        }
    }
    return c.out;
}

}  // namespace avrbench
