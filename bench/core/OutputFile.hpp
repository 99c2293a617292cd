// Files the bench writes for people and CI: VCD, gtkwave save files, HTML
// reports, JUnit, goldens, UART captures. Rules for every one of them:
//  - the target is checked before a run starts, so a bad path costs nothing
//    (check_output_path);
//  - content goes to a temporary file beside the target, which is renamed
//    over the target only when every write and the close succeeded; a failed
//    write leaves the target as it was;
//  - the bench removes only the temporary file it created itself, never the
//    target, and refuses targets that are not regular files (devices, FIFOs,
//    directories, symbolic links: never written through) or are read-only;
//    a file it replaces keeps its mode.
// Errors are BadInput "<what>: <path>: <reason>" (exit code 2).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace avrbench {

// Throws BadInput unless `path` can become a regular file: its folder exists
// and is a folder, and the path itself is absent or a regular file.
void check_output_path(const std::string& path, const std::string& what);

class OutputFile {
public:
    // Checks the target and opens the temporary file beside it.
    OutputFile(std::string path, std::string what);
    ~OutputFile();  // without commit(): removes the temporary file
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    std::FILE* stream() { return file_; }
    void write(std::string_view bytes);
    // Flushes, closes and renames into place; throws BadInput on any failure.
    void commit();

private:
    std::string path_;
    std::string what_;
    std::string temp_path_;
    std::FILE* file_ = nullptr;
};

// The whole file in one call.
void write_output_file(const std::string& path, std::string_view content, const std::string& what);

// The files one command reads and writes, checked together before it runs:
// no two outputs may be the same file (a VCD's .gtkw save file counts as an
// output), and no output may be one of the inputs - so `--vcd x --uart-out x`
// or `cam plot.nc` never overwrites what it reads or writes. "The same file":
// the same inode when it exists (hard and symbolic links included), else the
// same absolute, normalized path.
class RunFiles {
public:
    void input(const std::string& path, const std::string& what);
    // Also check_output_path().
    void output(const std::string& path, const std::string& what);
    // Every file of `other`, after this one's.
    void add(const RunFiles& other) { files_.insert(files_.end(), other.files_.begin(), other.files_.end()); }
    // Throws BadInput "<what>: <path> is also <other what>" for the first clash.
    void check() const;

private:
    struct Entry {
        std::string path, what, key;
        bool is_output;
    };
    std::vector<Entry> files_;
};

}  // namespace avrbench
