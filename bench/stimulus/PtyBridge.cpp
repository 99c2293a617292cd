#include "stimulus/PtyBridge.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/inotify.h>
#include <termios.h>
#include <unistd.h>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

namespace avrbench {
namespace {

// Output the host has not read is kept up to this much; beyond it the oldest
// is dropped (and counted), so a host that never reads cannot grow memory.
constexpr std::size_t kMaxPendingBytes = 1 << 20;
// What the host sent and the firmware has not taken yet: at most this much
// is read from the pty; the rest waits in the kernel's pty buffer and then
// blocks the host's writes, as a USB-serial bridge's small receive buffer
// throttles a real host (an FT232R holds 256 bytes, the Linux tty 4 KiB).
constexpr std::size_t kMaxQueuedToFirmware = 4096;

// --pty-link may replace a symbolic link to a pseudo-terminal (one a former
// run left), never a file or a link to anything else.
void check_link_path(const std::string& link) {
    struct stat st {};
    if (::lstat(link.c_str(), &st) != 0) return;  // free
    if (S_ISLNK(st.st_mode)) {
        char target[256] = {};
        const ssize_t n = ::readlink(link.c_str(), target, sizeof target - 1);
        if (n > 0 && std::string(target, static_cast<std::size_t>(n)).rfind("/dev/pts/", 0) == 0) return;
    }
    throw BadInput("--pty-link: " + escaped(link) +
                   " exists and is not a link to a pseudo-terminal (/dev/pts/N): avrbench replaces only such links");
}

}  // namespace

PtyBridge::PtyBridge(SerialLink& uart, const std::string& link_path) : uart_(uart), link_(link_path) {
    uart_.connect_host();
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) {
        const std::string why = std::strerror(errno);
        if (master_ >= 0) ::close(master_);
        throw BadInput("cannot open a pseudo-terminal: " + why);
    }
    const char* name = ::ptsname(master_);
    if (name == nullptr) {
        ::close(master_);
        throw BadInput("cannot name the pseudo-terminal");
    }
    path_ = name;
    slave_keepalive_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (slave_keepalive_ >= 0) {
        termios raw{};
        if (::tcgetattr(slave_keepalive_, &raw) == 0) {
            ::cfmakeraw(&raw);
            ::tcsetattr(slave_keepalive_, TCSANOW, &raw);
        }
    }
    // Watched after our own open, so only a host's opens count.
    inotify_ = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (inotify_ >= 0 && ::inotify_add_watch(inotify_, path_.c_str(), IN_OPEN) < 0) {
        ::close(inotify_);
        inotify_ = -1;
    }
    if (!link_.empty()) {
        check_link_path(link_);
        ::unlink(link_.c_str());
        if (::symlink(path_.c_str(), link_.c_str()) != 0) {
            const std::string why = std::strerror(errno);
            ::close(master_);
            if (slave_keepalive_ >= 0) ::close(slave_keepalive_);
            if (inotify_ >= 0) ::close(inotify_);
            throw BadInput(escaped(link_) + ": cannot link it to " + path_ + ": " + why);
        }
    }
    uart_.on_transmit([this](Cycle, std::uint8_t byte) {
        ++to_host_;
        pending_.push_back(static_cast<char>(byte));
        if (pending_.size() > kMaxPendingBytes) {
            dropped_ += pending_.size() - kMaxPendingBytes;
            pending_.erase(0, pending_.size() - kMaxPendingBytes);
        }
        flush();
    });
}

PtyBridge::~PtyBridge() {
    if (!link_.empty()) ::unlink(link_.c_str());
    if (slave_keepalive_ >= 0) ::close(slave_keepalive_);
    if (master_ >= 0) ::close(master_);
    if (inotify_ >= 0) ::close(inotify_);
}

bool PtyBridge::host_opened() {
    if (inotify_ < 0) return false;
    bool opened = false;
    alignas(inotify_event) char buf[4096];
    for (;;) {
        const ssize_t n = ::read(inotify_, buf, sizeof buf);
        if (n <= 0) break;
        for (ssize_t at = 0; at < n;) {
            const auto* e = reinterpret_cast<const inotify_event*>(buf + at);
            if (e->mask & IN_OPEN) opened = true;
            at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
        }
    }
    return opened;
}

void PtyBridge::flush() {
    while (!pending_.empty()) {
        const ssize_t n = ::write(master_, pending_.data(), pending_.size());
        if (n <= 0) return;  // the pty is full (EAGAIN): later
        pending_.erase(0, static_cast<std::size_t>(n));
    }
}

std::size_t PtyBridge::pump() {
    flush();
    std::string in;
    char buf[4096];
    while (uart_.pending_rx() + in.size() < kMaxQueuedToFirmware) {
        const std::size_t room = kMaxQueuedToFirmware - uart_.pending_rx() - in.size();
        const ssize_t n = ::read(master_, buf, std::min(room, sizeof buf));
        if (n <= 0) break;  // nothing (EAGAIN), or no host (EIO)
        in.append(buf, static_cast<std::size_t>(n));
    }
    if (!in.empty()) {
        uart_.send(in);
        to_firmware_ += in.size();
    }
    return in.size();
}

}  // namespace avrbench
