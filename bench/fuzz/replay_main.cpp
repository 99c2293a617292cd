// A parser's fuzz target run on files, without libFuzzer: each file (or each
// file in a folder) is one call of LLVMFuzzerTestOneInput, in the exact-size
// heap buffer libFuzzer would give it, so ASan sees a read past its end.
// The suite replays the inputs the campaigns keep (tests/fixtures/fuzz) and
// the seed corpus (the repository's boards, scenarios, goldens, ELFs, a VCD)
// in every build, the sanitized one included (tests/CMakeLists.txt:
// fuzz_replay.*); new inputs come from the campaigns (ci/fuzz). A target
// returns normally on bad input (BadInput is the expected answer); a crash,
// a sanitizer report or another exception ends this program, naming the file.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

std::vector<std::filesystem::path> inputs_of(const std::filesystem::path& arg) {
    std::vector<std::filesystem::path> files;
    if (std::filesystem::is_directory(arg)) {
        for (const auto& entry : std::filesystem::directory_iterator(arg)) {
            if (entry.is_regular_file()) files.push_back(entry.path());
        }
        std::sort(files.begin(), files.end());  // the same order on any file system
    } else if (std::filesystem::is_regular_file(arg)) {
        files.push_back(arg);
    }
    return files;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s FILE-OR-FOLDER...\n", argv[0]);
        return 2;
    }
    std::size_t replayed = 0;
    for (int a = 1; a < argc; ++a) {
        const std::vector<std::filesystem::path> files = inputs_of(argv[a]);
        if (files.empty()) {
            // A replay of nothing would pass without checking anything.
            std::fprintf(stderr, "%s: no input file at %s\n", argv[0], argv[a]);
            return 2;
        }
        for (const auto& file : files) {
            std::ifstream in(file, std::ios::binary);
            const std::vector<char> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
            const std::size_t size = bytes.size();
            const auto buffer = std::make_unique<std::uint8_t[]>(size);  // exactly the input's size
            std::copy(bytes.begin(), bytes.end(), buffer.get());
            try {
                LLVMFuzzerTestOneInput(buffer.get(), size);
            } catch (const std::exception& e) {
                std::fprintf(stderr, "%s: %s: uncaught exception: %s\n", argv[0], file.c_str(), e.what());
                return 1;
            }
            ++replayed;
        }
    }
    std::printf("%s: %zu inputs replayed\n", argv[0], replayed);
    return 0;
}
