// `avrbench fuzz` (bench/tools/FuzzCommand.cpp).
#pragma once

#include <string>

namespace avrbench {

struct FuzzArgs {
    std::string elf;
    std::string board;
    std::string duration = "60s";  // wall-clock time of the campaign
    std::string bound = "5s";      // simulated time one input may take
    std::string out = "fuzz-out";
    int jobs = 1;
    unsigned seed = 1;
};

// Exit 0: nothing found; 1: findings (listed); BadInput for bad arguments.
int fuzz_command(const FuzzArgs& args);

}  // namespace avrbench
