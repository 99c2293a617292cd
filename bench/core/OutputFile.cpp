#include "core/OutputFile.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"

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
    if (path.back() == '/') throw BadInput(what + ": " + escaped(path) + ": names a folder, not a file");
    const std::string folder = folder_of(path);
    struct stat st {};
    if (::stat(folder.c_str(), &st) != 0) {
        throw BadInput(what + ": " + escaped(path) + ": the folder " + escaped(folder) + " does not exist");
    }
    if (!S_ISDIR(st.st_mode)) throw BadInput(what + ": " + escaped(path) + ": " + escaped(folder) + " is not a folder");
    if (::access(folder.c_str(), W_OK) != 0) throw BadInput(what + ": " + escaped(path) + ": the folder " + escaped(folder) + " is not writable");
    if (::lstat(path.c_str(), &st) == 0) {
        // A link is refused, whatever it points to: replacing it would put the
        // output where the link is (/dev/stderr is one) and leave its target
        // as it was, which is neither what the name promised nor safe.
        if (S_ISLNK(st.st_mode)) {
            throw BadInput(what + ": " + escaped(path) + ": is a symbolic link; the bench writes only to a file of its own name");
        }
        if (S_ISDIR(st.st_mode)) throw BadInput(what + ": " + escaped(path) + ": is a folder");
        if (!S_ISREG(st.st_mode)) throw BadInput(what + ": " + escaped(path) + ": is not a regular file (a device, FIFO or socket)");
        if ((st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0) {
            throw BadInput(what + ": " + escaped(path) + ": is read-only (no write permission); the bench does not replace it");
        }
    }
}

OutputFile::OutputFile(std::string path, std::string what) : path_(std::move(path)), what_(std::move(what)) {
    check_output_path(path_, what_);
    const std::string name = fs::path(path_).filename().string();
    std::string pattern = (fs::path(folder_of(path_)) / ("." + name.substr(0, 100) + ".tmp-XXXXXX")).string();
    std::vector<char> buf(pattern.begin(), pattern.end());
    buf.push_back('\0');
    const int fd = ::mkstemp(buf.data());
    if (fd < 0) throw BadInput(what_ + ": " + escaped(path_) + ": cannot create a file there: " + std::strerror(errno));
    temp_path_ = buf.data();
    // A file written anew: 0644 (as the umask allows); one replaced keeps its mode.
    struct stat existing {};
    if (::stat(path_.c_str(), &existing) == 0 && S_ISREG(existing.st_mode)) {
        ::fchmod(fd, existing.st_mode & 07777);
    } else {
        const mode_t mask = ::umask(0);
        ::umask(mask);
        ::fchmod(fd, 0644 & ~mask);
    }
    file_ = ::fdopen(fd, "wb");
    if (file_ == nullptr) {
        ::close(fd);
        ::unlink(temp_path_.c_str());
        throw BadInput(what_ + ": " + escaped(path_) + ": cannot open for writing");
    }
}

OutputFile::~OutputFile() {
    if (file_ != nullptr) std::fclose(file_);
    if (!temp_path_.empty()) ::unlink(temp_path_.c_str());  // ours: created by mkstemp above
}

void OutputFile::write(std::string_view bytes) {
    if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
        throw BadInput(what_ + ": " + escaped(path_) + ": write failed: " + std::strerror(errno));
    }
}

void OutputFile::commit() {
    const bool write_error = std::ferror(file_) != 0 || std::fflush(file_) != 0;
    const int saved = errno;
    const bool close_error = std::fclose(file_) != 0;
    file_ = nullptr;
    if (write_error || close_error) {
        throw BadInput(what_ + ": " + escaped(path_) + ": write failed: " + std::strerror(write_error ? saved : errno));
    }
    if (::rename(temp_path_.c_str(), path_.c_str()) != 0) {
        throw BadInput(what_ + ": " + escaped(path_) + ": cannot replace the file: " + std::strerror(errno));
    }
    temp_path_.clear();
}

void write_output_file(const std::string& path, std::string_view content, const std::string& what) {
    OutputFile out(path, what);
    out.write(content);
    out.commit();
}

namespace {

// What makes two names the same file: device and inode of an existing file
// (following links), else the normalized absolute path.
std::string identity_of(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) return "inode:" + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
    std::error_code ec;
    const fs::path absolute = fs::weakly_canonical(fs::absolute(path, ec), ec);
    return "path:" + absolute.lexically_normal().string();
}

}  // namespace

void RunFiles::input(const std::string& path, const std::string& what) {
    if (!path.empty()) files_.push_back({path, what, identity_of(path), false});
}

void RunFiles::output(const std::string& path, const std::string& what) {
    check_output_path(path, what);
    files_.push_back({path, what, identity_of(path), true});
}

void RunFiles::check() const {
    for (std::size_t i = 0; i < files_.size(); ++i) {
        if (!files_[i].is_output) continue;
        for (std::size_t j = 0; j < files_.size(); ++j) {
            if (j == i || (files_[j].is_output && j > i) || files_[j].key != files_[i].key) continue;
            throw BadInput(files_[i].what + ": " + escaped(files_[i].path) + " is also " +
                           (files_[j].is_output ? "written as " : "read as ") + files_[j].what +
                           (files_[j].path != files_[i].path ? " (" + escaped(files_[j].path) + ")" : "") +
                           "; give each output a file of its own");
        }
    }
}

}  // namespace avrbench
