#include "debug/GdbConnection.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/Errors.hpp"

namespace avrbench {

GdbListener::GdbListener(int port) {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd_ < 0) throw BadInput(std::string("--gdb: cannot open a socket: ") + std::strerror(errno));
    const int yes = 1;
    ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(static_cast<std::uint16_t>(port));
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd_, 1) != 0) {
        const std::string why = std::strerror(errno);
        ::close(fd_);
        fd_ = -1;
        throw BadInput("--gdb: cannot listen on 127.0.0.1:" + std::to_string(port) + ": " + why);
    }
    socklen_t len = sizeof addr;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
}

GdbListener::~GdbListener() {
    if (fd_ >= 0) ::close(fd_);
}

int GdbListener::accept_one(std::chrono::seconds timeout) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(timeout.count() * 1000));
    if (ready <= 0) return -1;
    const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd >= 0) {
        const int yes = 1;
        // Replies are small and each waits for the next request: no Nagle delay.
        ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
    }
    return fd;
}

GdbConnection::~GdbConnection() { close(); }

void GdbConnection::close() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
}

int GdbConnection::read_byte() {
    if (unread() == 0) {
        pending_.clear();
        head_ = 0;
        if (fd_ < 0) return -1;
        char buf[4096];
        for (;;) {
            const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
            if (n > 0) {
                pending_.assign(buf, static_cast<std::size_t>(n));
                break;
            }
            if (n < 0 && errno == EINTR) continue;
            close();
            return -1;
        }
    }
    const unsigned char c = static_cast<unsigned char>(pending_[head_++]);
    if (head_ > 4096 && head_ * 2 > pending_.size()) {
        pending_.erase(0, head_);
        head_ = 0;
    }
    return c;
}

bool GdbConnection::poll_interrupt() {
    if (fd_ < 0) return false;
    pollfd p{fd_, POLLIN, 0};
    while (::poll(&p, 1, 0) > 0) {
        char buf[256];
        const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
        if (n <= 0) {
            close();
            return false;
        }
        pending_.append(buf, static_cast<std::size_t>(n));
    }
    const auto at = pending_.find('\x03', head_);
    if (at == std::string::npos) return false;
    pending_.erase(at, 1);
    return true;
}

std::optional<std::string> GdbConnection::read_packet() {
    for (;;) {
        int c = read_byte();
        if (c < 0) return std::nullopt;
        if (c == 0x03) return std::string("\x03");
        if (c != '$') continue;  // acknowledgements and noise between packets
        std::string payload;
        unsigned sum = 0;
        while ((c = read_byte()) >= 0 && c != '#') {
            sum += static_cast<unsigned>(c);
            if (c == '}') {  // escape: the next byte xor 0x20
                const int e = read_byte();
                if (e < 0) return std::nullopt;
                sum += static_cast<unsigned>(e);
                payload += static_cast<char>(e ^ 0x20);
            } else {
                payload += static_cast<char>(c);
            }
        }
        if (c < 0) return std::nullopt;
        const int h = read_byte(), l = read_byte();
        if (h < 0 || l < 0) return std::nullopt;
        const std::string received = from_hex(std::string{static_cast<char>(h), static_cast<char>(l)});
        const bool good = received.size() == 1 && static_cast<unsigned char>(received[0]) == (sum & 0xFF);
        if (!no_ack_) {
            const char ack = good ? '+' : '-';
            if (::send(fd_, &ack, 1, MSG_NOSIGNAL) != 1) close();
            if (!good) continue;  // the debugger sends it again
        }
        return payload;
    }
}

void GdbConnection::send_packet(const std::string& payload) {
    if (fd_ < 0) return;
    unsigned sum = 0;
    std::string frame = "$";
    for (char c : payload) {
        if (c == '$' || c == '#' || c == '}' || c == '*') {
            frame += '}';
            frame += static_cast<char>(c ^ 0x20);
            sum += '}' + static_cast<unsigned char>(c ^ 0x20);
        } else {
            frame += c;
            sum += static_cast<unsigned char>(c);
        }
    }
    static const char digits[] = "0123456789abcdef";
    frame += '#';
    frame += digits[(sum >> 4) & 0xF];
    frame += digits[sum & 0xF];
    for (int attempt = 0; attempt < 3; ++attempt) {
        std::size_t sent = 0;
        while (sent < frame.size()) {
            const ssize_t n = ::send(fd_, frame.data() + sent, frame.size() - sent, MSG_NOSIGNAL);
            if (n <= 0) {
                if (n < 0 && errno == EINTR) continue;
                close();
                return;
            }
            sent += static_cast<std::size_t>(n);
        }
        if (no_ack_) return;
        // The acknowledgement; anything else that comes first is kept, in
        // front of what is still unread.
        std::string kept;
        int c = 0;
        while ((c = read_byte()) >= 0 && c != '+' && c != '-') kept += static_cast<char>(c);
        if (!kept.empty()) {
            pending_ = kept + pending_.substr(head_);
            head_ = 0;
        }
        if (c != '-') return;
    }
}

std::string to_hex(const std::string& bytes) {
    static const char digits[] = "0123456789abcdef";
    std::string out;
    out.reserve(bytes.size() * 2);
    for (unsigned char b : bytes) {
        out += digits[b >> 4];
        out += digits[b & 0xF];
    }
    return out;
}

namespace {
int hex_value(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}
}  // namespace

std::string from_hex(const std::string& hex) {
    std::string out;
    for (std::size_t i = 0; i + 1 < hex.size(); i += 2) {
        const int h = hex_value(hex[i]), l = hex_value(hex[i + 1]);
        if (h < 0 || l < 0) break;
        out += static_cast<char>(h * 16 + l);
    }
    return out;
}

}  // namespace avrbench
