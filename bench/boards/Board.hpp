// A board built from a board file: its MCUs with their firmware, its parts and
// its nets, advanced together in simulated time.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "mcu/Lockstep.hpp"
#include "mcu/Mcu.hpp"
#include "periph/twi/Twi.hpp"
#include "parts/Part.hpp"
#include "wiring/McuPinTerminal.hpp"
#include "wiring/Net.hpp"

namespace avrbench {

class Board {
public:
    // `firmware` maps MCU name to ELF path; an MCU missing there uses the
    // board file's `firmware:`. Throws BadInput (one line, file:line where it
    // applies) for unknown part types, parameters, part pins, nets with two
    // drivers, circular part references, a firmware built for another MCU.
    Board(BoardSpec spec, const std::map<std::string, std::string>& firmware);
    static std::unique_ptr<Board> from_file(const std::string& path, const std::map<std::string, std::string>& firmware);
    ~Board();
    Board(const Board&) = delete;
    Board& operator=(const Board&) = delete;

    const BoardSpec& spec() const { return spec_; }

    // The MCU by name; "" is the board's first (for single-MCU boards).
    Mcu& mcu(const std::string& name = "");
    std::vector<Mcu*> mcus() const;
    Part& part(const std::string& name);
    template <class T>
    T& part_as(const std::string& name) {
        auto* p = dynamic_cast<T*>(&part(name));
        if (p == nullptr) throw BadInput("part '" + name + "' is not of the requested type");
        return *p;
    }
    std::vector<Part*> parts() const;
    template <class T>
    std::vector<T*> parts_of_type() const {
        std::vector<T*> out;
        for (const auto& p : parts_) {
            if (auto* t = dynamic_cast<T*>(p.get())) out.push_back(t);
        }
        return out;
    }
    // "uno.PD2", or a label name from the board file.
    Pin& pin(const std::string& endpoint_or_label);
    // Whether MCU pins hand a repeating timer output to their nets as one
    // periodic wave (periph/timer/PeriodicOutput.hpp; on by default). Off: every edge
    // goes through the net (`avrbench run --no-periodic-waves`).
    void set_periodic_waves(bool on);
    // Drives an MCU pin from outside (a scenario's stimulus) as a push-pull
    // source on the pin's net, or lets go of it; a pin on no net gets one.
    void drive_pin(const std::string& endpoint_or_label, bool level);
    void release_pin(const std::string& endpoint_or_label);
    const std::vector<std::unique_ptr<Net>>& nets() const { return nets_; }
    // I2C buses: the MCUs whose TWI SDA and SCL pins share nets.
    const std::vector<std::unique_ptr<TwiBus>>& twi_buses() const { return twi_buses_; }

    Lockstep& lockstep() { return lockstep_; }
    // Advances every MCU to `end_ps` of simulated time: afterwards now_ps() >=
    // end_ps exactly, unless the board halted or a callback asked to stop.
    StopReason run_until_ps(Picoseconds end_ps) { return lockstep_.run_until_ps(end_ps); }
    // Ends the present run_until_ps after the running MCU's instruction (Lockstep::request_stop).
    void request_stop() { lockstep_.request_stop(); }
    // The time of the MCU furthest behind.
    Picoseconds now_ps() const { return lockstep_.now_ps(); }
    // Conveniences for a single call (never for a loop's condition).
    StopReason run_until_seconds(double seconds);
    StopReason run_for_seconds(double seconds);
    double now_seconds() const { return seconds_from_ps(now_ps()); }

    // Every finding of every MCU and part, in the order they happened per source.
    std::vector<Finding> findings() const;
    // How many there are (cheap: nothing is copied).
    std::size_t finding_count() const;

private:
    void build_mcus(const std::map<std::string, std::string>& firmware);
    void build_parts();
    void build_nets();
    // A port that requires an interface, joined to the part that provides it.
    struct PortLink {
        Part* part;
        std::size_t port;
        Part* provider;
        std::size_t provider_port;
    };
    void build_net(const NetDecl& decl, std::vector<PortLink>& links);
    void connect_ports(const std::vector<PortLink>& links);
    void set_net_clocks();
    void build_electrical_net(const NetDecl& decl);
    void build_analog_net(const NetDecl& decl, Part& source, std::size_t port, const std::vector<const Endpoint*>& pins);
    void build_twi_buses();
    void declare_influences();
    Net* net_of(Mcu& mcu, const std::string& pin_name) const;
    McuPinTerminal& add_mcu_terminal(Mcu& mcu, Pin& pin, Net& net);
    Terminal& stimulus_for(const std::string& endpoint_or_label);

    BoardSpec spec_;
    std::vector<std::unique_ptr<Mcu>> mcus_;  // first member: destroyed last
    std::vector<std::unique_ptr<Part>> parts_;
    std::map<const Mcu*, std::unique_ptr<McuPortWatch>> port_watches_;
    std::vector<std::unique_ptr<McuPinTerminal>> mcu_terminals_;
    std::map<const Pin*, std::unique_ptr<Terminal>> stimuli_;
    std::vector<std::unique_ptr<Net>> nets_;
    bool periodic_waves_ = true;
    std::vector<std::unique_ptr<TwiBus>> twi_buses_;
    Lockstep lockstep_;
};

}  // namespace avrbench
