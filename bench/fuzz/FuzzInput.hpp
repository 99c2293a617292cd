// What every fuzz target shares: the input as a file when the parser reads
// files, and the rule that BadInput is the expected answer to bad input.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace avrbench::fuzz {

// A file holding the input, removed when this goes out of scope.
class InputFile {
public:
    InputFile(const std::uint8_t* data, std::size_t size, const char* suffix) {
        path_ = "/tmp/avrbench-fuzz-" + std::to_string(::getpid()) + suffix;
        if (std::FILE* f = std::fopen(path_.c_str(), "wb")) {
            if (size > 0) std::fwrite(data, 1, size, f);
            std::fclose(f);
        }
    }
    ~InputFile() { std::remove(path_.c_str()); }
    const std::string& path() const { return path_; }

private:
    std::string path_;
};

}  // namespace avrbench::fuzz
