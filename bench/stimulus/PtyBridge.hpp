// A pseudo-terminal bridged to one USART of an emulated MCU, the way simavr's
// uart_pty and MK404 offer one: host software (a terminal, avrdude, a
// G-code sender) opens the pty's path as if it were the board's USB serial
// port. Bytes the host writes go to the firmware's receiver (paced by the
// USART's own frame timing); bytes the firmware transmits are written to the
// host. The pty is raw (no echo, no line editing). pump() moves the host's
// bytes in; call it between slices of simulated time.
#pragma once

#include <cstdint>
#include <string>

#include "core/SerialLink.hpp"

namespace avrbench {

class PtyBridge {
public:
    // Opens the pty; with `link_path`, also makes a symlink to it there
    // (replacing an existing link). Throws BadInput when it cannot.
    PtyBridge(SerialLink& uart, const std::string& link_path = "");
    ~PtyBridge();
    PtyBridge(const PtyBridge&) = delete;
    PtyBridge& operator=(const PtyBridge&) = delete;

    const std::string& path() const { return path_; }
    // Reads what the host wrote and queues it for the firmware; flushes what
    // the firmware sent that the host has not taken yet. Returns the bytes queued.
    std::size_t pump();
    std::uint64_t bytes_to_firmware() const { return to_firmware_; }
    std::uint64_t bytes_to_host() const { return to_host_; }
    std::uint64_t bytes_dropped() const { return dropped_; }
    // True once for every time host software opened the pty since the last
    // call (inotify's IN_OPEN on the slave device). A pty carries no DTR or
    // RTS a host could toggle (Linux pty drivers reject the modem-control
    // ioctls), so "the host opened the port" stands in for the DTR edge an
    // Arduino's auto-reset capacitor turns into a RESET pulse.
    bool host_opened();

private:
    void flush();

    SerialLink& uart_;
    int master_ = -1;
    int slave_keepalive_ = -1;  // our own slave fd: reads do not fail while no host has it open
    int inotify_ = -1;          // IN_OPEN on the slave device, for host_opened()
    std::string path_, link_;
    std::string pending_;       // firmware output the pty could not take yet
    std::uint64_t to_firmware_ = 0, to_host_ = 0, dropped_ = 0;
};

}  // namespace avrbench
