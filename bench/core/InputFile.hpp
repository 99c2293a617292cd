// Files the bench reads because a user named them: board files, scenarios,
// goldens, G-code, --uart-in bytes, boot loader images. Rules for every one:
//  - opened without blocking (O_NONBLOCK), so a FIFO or a device never
//    stalls a run, and accepted only when it is a regular file (a FIFO,
//    device, socket or folder is one BadInput line);
//  - read up to a cap the kind of file documents (kMax*Bytes below,
//    docs/CLI.md "Limits"); a larger file is refused before a byte of it is
//    read, so neither /dev/zero nor a sparse multi-gigabyte file can fill
//    memory;
//  - errors are BadInput "<what>: <path>: <reason>" (exit code 2), the path
//    quoted with escapes where it holds anything but printable characters.
#pragma once

#include <cstdint>
#include <string>

namespace avrbench {

// Caps per kind of input (docs/CLI.md, "Limits").
inline constexpr std::uint64_t kMaxBoardFileBytes = 1u << 20;      // 1 MiB: the largest standard board is 9 kB
inline constexpr std::uint64_t kMaxScenarioFileBytes = 1u << 20;   // 1 MiB
inline constexpr std::uint64_t kMaxGoldenFileBytes = 256u << 20;   // 256 MiB: ~25 M changes at ~10 bytes each
inline constexpr std::uint64_t kMaxGcodeFileBytes = 64u << 20;     // 64 MiB: a long print is a few MB
inline constexpr std::uint64_t kMaxUartInputBytes = 16u << 20;     // 16 MiB: 28 min of 115200 baud
inline constexpr std::uint64_t kMaxBootloaderFileBytes = 4u << 20; // 4 MiB: an Intel HEX of a 256 KiB flash is ~720 kB
inline constexpr std::uint64_t kMaxDxfFileBytes = 64u << 20;       // 64 MiB: a plotter drawing is kilobytes
inline constexpr std::uint64_t kMaxVcdFileBytes = 1u << 30;        // 1 GiB: what read_vcd parses in memory

// The whole file, checked as above; `what` names it in errors ("--gcode",
// "board file", "golden timeline").
std::string read_input_file(const std::string& path, const std::string& what, std::uint64_t max_bytes);
// The same checks without reading: for inputs checked before a run starts.
void check_input_file(const std::string& path, const std::string& what, std::uint64_t max_bytes);

// `text` as one line for a message: printable ASCII as it is, anything else
// (newlines, escape sequences, bytes above 0x7e) as \n, \t, \xNN, so an error
// naming a user's string can never span lines or drive the terminal.
std::string escaped(const std::string& text);
// The same in single quotes, a quote inside written \'.
std::string quoted_text(const std::string& text);
// Bytes as one line (a serial transcript): printable ASCII as it is, every
// other byte as \xNN, line ends included.
std::string hex_escaped(const std::string& bytes);

}  // namespace avrbench
