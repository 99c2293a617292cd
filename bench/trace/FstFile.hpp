// FST, gtkwave's compressed dump format, for `--vcd NAME.fst`: the run's
// VCD is written beside it as usual (streamed) and converted at the end by
// vcd2fst from Debian's gtkwave package (gtkwave's own FST writer, fstapi),
// then removed. A periodic waveform shrinks the most: Teacup's 150 s
// heat-up with every pin traced is a 392 MB VCD and a 423 KB FST.
#pragma once

#include <string>

namespace avrbench {

// The path names an FST file (its extension is .fst, any case).
bool is_fst_path(const std::string& path);

// vcd2fst's path on PATH, or BadInput naming the package that has it.
std::string vcd2fst_program(const std::string& option);

// Where the VCD for an FST `fst_path` is written meanwhile: a hidden file
// beside it, named with the process id (BadInput if that exists).
std::string vcd_for_fst(const std::string& fst_path);

// Converts `vcd_path` into `fst_path` (written beside it and renamed into
// place when complete), then removes the VCD. BadInput when vcd2fst fails.
void convert_vcd_to_fst(const std::string& vcd_path, const std::string& fst_path, const std::string& option);

}  // namespace avrbench
