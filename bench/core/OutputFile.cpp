#include "core/OutputFile.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "core/Errors.hpp"

namespace fs = std::filesystem;

namespace avrbench {
namespace {

std::string folder_of(const std::string& path) {
    const fs::path parent = fs::path(path).parent_path();
    return parent.empty() ? std::string(".") : parent.string();
}

}  // namespace

void check_output_path(const std::string& path, const std::string& what) {
    if (path.empty()) throw BadInput(what + ": an empty file name");
    if (path.back() == '/') throw BadInput(what + ": " + path + ": names a folder, not a file");
    const std::string folder = folder_of(path);
    struct stat st {};
    if (::stat(folder.c_str(), &st) != 0) {
        throw BadInput(what + ": " + path + ": the folder " + folder + " does not exist");
    }
    if (!S_ISDIR(st.st_mode)) throw BadInput(what + ": " + path + ": " + folder + " is not a folder");
    if (::access(folder.c_str(), W_OK) != 0) throw BadInput(what + ": " + path + ": the folder " + folder + " is not writable");
    if (::lstat(path.c_str(), &st) == 0) {
        if (S_ISLNK(st.st_mode) && ::stat(path.c_str(), &st) != 0) return;  // a dangling link: replaced by the file
        if (S_ISDIR(st.st_mode)) throw BadInput(what + ": " + path + ": is a folder");
        if (!S_ISREG(st.st_mode)) throw BadInput(what + ": " + path + ": is not a regular file (a device, FIFO or socket)");
    }
}

OutputFile::OutputFile(std::string path, std::string what) : path_(std::move(path)), what_(std::move(what)) {
    check_output_path(path_, what_);
    const std::string name = fs::path(path_).filename().string();
    std::string pattern = (fs::path(folder_of(path_)) / ("." + name.substr(0, 100) + ".tmp-XXXXXX")).string();
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    const int fd = ::mkstemp(buf.data());
    if (fd < 0) throw BadInput(what_ + ": " + path_ + ": cannot create a file there: " + std::strerror(errno));
    temp_path_ = buf.data();
    ::fchmod(fd, 0644);
    file_ = ::fdopen(fd, "wb");
    if (file_ == nullptr) {
        ::close(fd);
        ::unlink(temp_path_.c_str());
        throw BadInput(what_ + ": " + path_ + ": cannot open for writing");
    }
}

OutputFile::~OutputFile() {
    if (file_ != nullptr) std::fclose(file_);
    if (!temp_path_.empty()) ::unlink(temp_path_.c_str());  // ours: created by mkstemp above
}

void OutputFile::write(std::string_view bytes) {
    if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
        throw BadInput(what_ + ": " + path_ + ": write failed: " + std::strerror(errno));
    }
}

void OutputFile::commit() {
    const bool write_error = std::ferror(file_) != 0 || std::fflush(file_) != 0;
    const int saved = errno;
    const bool close_error = std::fclose(file_) != 0;
    file_ = nullptr;
    if (write_error || close_error) {
        throw BadInput(what_ + ": " + path_ + ": write failed: " + std::strerror(write_error ? saved : errno));
    }
    if (::rename(temp_path_.c_str(), path_.c_str()) != 0) {
        throw BadInput(what_ + ": " + path_ + ": cannot replace the file: " + std::strerror(errno));
    }
    temp_path_.clear();
}

void write_output_file(const std::string& path, std::string_view content, const std::string& what) {
    OutputFile out(path, what);
    out.write(content);
    out.commit();
}

}  // namespace avrbench
