#include "core/InputFile.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "core/Errors.hpp"

namespace avrbench {
namespace {

std::string kind_of(mode_t mode) {
    if (S_ISDIR(mode)) return "a folder";
    if (S_ISFIFO(mode)) return "a FIFO";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "not a regular file";
}

std::string size_text(std::uint64_t bytes) {
    char text[32];
    if (bytes >= (1u << 20)) {
        std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1u << 20));
    } else {
        std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
    }
    return text;
}

struct Fd {
    int fd = -1;
    Fd() = default;
    Fd(Fd&& other) noexcept : fd(other.fd) { other.fd = -1; }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    Fd& operator=(Fd&&) = delete;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

}  // namespace

std::string hex_escaped(const std::string& bytes) {
    std::string out;
    out.reserve(bytes.size());
    for (char ch : bytes) {
        const auto c = static_cast<unsigned char>(ch);
        if (c >= 0x20 && c < 0x7f) {
            out.push_back(ch);
        } else {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", c);
            out += buf;
        }
    }
    return out;
}

std::string escaped(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        const auto u = static_cast<unsigned char>(c);
        if (c == '\n') {
            out += "\\n";
        } else if (c == '\t') {
            out += "\\t";
        } else if (c == '\r') {
            out += "\\r";
        } else if (u < 0x20 || u > 0x7e) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", u);
            out += buf;
        } else {
            out.push_back(c);
        }
    }
    return out;
}

std::string quoted_text(const std::string& text) {
    std::string out = "'";
    for (char c : escaped(text)) {
        if (c == '\'') out.push_back('\\');
        out.push_back(c);
    }
    out.push_back('\'');
    return out;
}

namespace {

// Opens and checks `path` as above; the descriptor and the file's size.
Fd open_checked(const std::string& path, const std::string& what, std::uint64_t max_bytes, std::uint64_t& size) {
    const std::string name = what + ": " + escaped(path);
    if (path.empty()) throw BadInput(what + ": an empty file name");
    Fd file;
    file.fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (file.fd < 0) {
        if (errno == ENOENT) throw BadInput(name + ": no such file");
        throw BadInput(name + ": cannot open: " + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(file.fd, &st) != 0) throw BadInput(name + ": cannot read: " + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) throw BadInput(name + ": is " + kind_of(st.st_mode) + ", not a regular file");
    size = static_cast<std::uint64_t>(st.st_size);
    if (size > max_bytes) {
        throw BadInput(name + ": " + size_text(size) + " is more than a " + what + " may be (" + size_text(max_bytes) +
                       "; docs/CLI.md, \"Limits\")");
    }
    return file;
}

}  // namespace

void check_input_file(const std::string& path, const std::string& what, std::uint64_t max_bytes) {
    std::uint64_t size = 0;
    open_checked(path, what, max_bytes, size);
}

std::string read_input_file(const std::string& path, const std::string& what, std::uint64_t max_bytes) {
    std::uint64_t size = 0;
    const Fd file = open_checked(path, what, max_bytes, size);
    std::string bytes(static_cast<std::size_t>(size), '\0');
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(file.fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw BadInput(what + ": " + escaped(path) + ": cannot read: " + std::strerror(errno));
        if (n == 0) break;  // shrank while reading: what was there
        done += static_cast<std::size_t>(n);
    }
    bytes.resize(done);
    return bytes;
}

}  // namespace avrbench
