// Files the bench writes for people and CI: VCD, gtkwave save files, HTML
// reports, JUnit, goldens, UART captures. Rules for every one of them:
//  - the target is checked before a run starts, so a bad path costs nothing
//    (check_output_path);
//  - content goes to a temporary file beside the target, which is renamed
//    over the target only when every write and the close succeeded; a failed
//    write leaves the target as it was;
//  - the bench removes only the temporary file it created itself, never the
//    target, and refuses targets that are not regular files (devices, FIFOs,
//    directories).
// Errors are BadInput "<what>: <path>: <reason>" (exit code 2).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

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

}  // namespace avrbench
