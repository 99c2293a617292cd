// One GDB remote serial protocol connection over TCP on localhost: the
// packet framing of the protocol ("$data#checksum", '+'/'-' acknowledgements
// until QStartNoAckMode, the 0x03 interrupt byte, run-length-free replies,
// binary escapes for X packets). What the packets mean is Debugger's.
// Source: the GDB manual, appendix E "GDB Remote Serial Protocol"
// (sourceware.org/gdb/current/onlinedocs/gdb/Remote-Protocol.html).
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace avrbench {

class GdbListener {
public:
    // Listens on 127.0.0.1:`port` (0 = a free port the system picks).
    // Throws BadInput when the port cannot be had.
    explicit GdbListener(int port);
    ~GdbListener();
    GdbListener(const GdbListener&) = delete;
    GdbListener& operator=(const GdbListener&) = delete;
    int port() const { return port_; }
    // Waits for avr-gdb to connect (wall time: a person starting a
    // debugger); the connected socket, or -1 after `timeout`.
    int accept_one(std::chrono::seconds timeout);

private:
    int fd_ = -1;
    int port_ = 0;
};

class GdbConnection {
public:
    explicit GdbConnection(int fd) : fd_(fd) {}
    ~GdbConnection();
    GdbConnection(const GdbConnection&) = delete;
    GdbConnection& operator=(const GdbConnection&) = delete;

    bool open() const { return fd_ >= 0; }
    // The next packet's payload (escapes undone), blocking; nullopt when the
    // connection closed. A lone 0x03 (interrupt) comes back as "\x03".
    std::optional<std::string> read_packet();
    // True when the debugger sent an interrupt (0x03) since the last call;
    // does not block. Other bytes that arrive are kept for read_packet.
    bool poll_interrupt();
    void send_packet(const std::string& payload);
    void set_no_ack() { no_ack_ = true; }
    void close();

private:
    int read_byte();  // -1 when closed
    std::size_t unread() const { return pending_.size() - head_; }
    int fd_;
    bool no_ack_ = false;
    // Bytes read and not yet consumed, from head_ on: consuming one moves
    // head_ (the buffer is compacted when the consumed half is the larger),
    // so a burst of input costs its length, not its length squared.
    std::string pending_;
    std::size_t head_ = 0;
};

// Hex helpers of the protocol.
std::string to_hex(const std::string& bytes);
std::string from_hex(const std::string& hex);  // stops at the first non-hex pair

}  // namespace avrbench
