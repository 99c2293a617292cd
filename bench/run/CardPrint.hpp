// A host's lines that print a file from the machine's SD card (Marlin,
// Prusa, Repetier, Sprinter, Teacup: M23 selects a file by its name, M24
// starts or resumes the print), and the selected file's lines, found on the
// board's cards, so the motion judges are told the file's moves when the
// firmware starts it.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "parts/StoredFiles.hpp"

namespace avrbench {

struct CardPrintCommand {
    enum class Kind { Select, Start };
    Kind kind;
    std::string file;  // Select: the name as sent ("job.gco", "/JOB.GCO")
};

// M23 <name> or M24 (a line number "N12 " before and a checksum "*71" after
// are allowed); empty for any other line.
std::optional<CardPrintCommand> card_print_command(std::string_view line);

// The file named `file` (case-insensitive, a leading '/' ignored) on the
// first card that has it; empty with `why` when none does or none can be read.
std::optional<std::string> card_file(const std::vector<const StoredFiles*>& cards, const std::string& file, std::string& why);

}  // namespace avrbench
