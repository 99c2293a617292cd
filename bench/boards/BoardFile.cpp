#include "boards/BoardFile.hpp"

#include "parts/HostConnector.hpp"
#include "boards/YamlKeys.hpp"

#include "core/Time.hpp"

#include <cstdio>
#include <cstdlib>

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <map>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>

#include "core/Errors.hpp"
#include "core/InputFile.hpp"
#include "periph/ports/McuPins.hpp"
#include "core/Notice.hpp"
#include "parts/PartRegistry.hpp"
#include "core/Units.hpp"

namespace avrbench {
namespace {

bool valid_name(const std::string& name) {
    if (name.empty() || !(std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_')) return false;
    for (char c : name) {
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
    }
    return true;
}

Endpoint parse_endpoint(const YAML::Node& node, const std::string& path) {
    const std::string text = yaml_scalar(node, path, "a net endpoint");
    const auto dot = text.find('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == text.size() || text.find('.', dot + 1) != std::string::npos) {
        throw BadInput(yaml_where(path, node) + ": '" + text + "' is not an endpoint (expected mcu.PIN or part.pin)");
    }
    return Endpoint{text.substr(0, dot), text.substr(dot + 1), yaml_where(path, node)};
}

void check_name(const std::string& name, const std::string& location, const char* what, std::set<std::string>& seen) {
    if (!valid_name(name)) throw BadInput(location + ": " + quoted_text(name) + " is not a valid " + what + " name");
    if (!seen.insert(name).second) throw BadInput(location + ": duplicate name '" + name + "'");
}

// Checks an MCU endpoint's pin against the MCU's pin-out.
void check_mcu_pin(const Endpoint& e, const McuDecl& mcu) {
    const std::string& pin = e.pin;
    const bool shape = pin.size() == 3 && pin[0] == 'P' && std::isupper(static_cast<unsigned char>(pin[1])) &&
                       std::isdigit(static_cast<unsigned char>(pin[2]));
    const bool too_high = pin.size() >= 3 && pin[0] == 'P' && std::isdigit(static_cast<unsigned char>(pin[2])) &&
                          pin.size() > 3;
    if (too_high || (shape && !mcu_has_pin(mcu.type, pin[1], pin[2] - '0'))) {
        throw BadInput(e.location + ": unknown pin '" + pin + "': " + mcu.type + " has no such pin");
    }
    if (!shape) throw BadInput(e.location + ": '" + pin + "' is not an MCU pin name (expected e.g. PD2)");
}

}  // namespace

const McuDecl* BoardSpec::find_mcu(const std::string& n) const {
    for (const auto& m : mcus) {
        if (m.name == n) return &m;
    }
    return nullptr;
}

const PartDecl* BoardSpec::find_part(const std::string& n) const {
    for (const auto& p : parts) {
        if (p.name == n) return &p;
    }
    return nullptr;
}

bool BoardSpec::has_serial_port() const {
    for (const auto& part : parts) {
        const auto type = part_types().find(part.type);
        if (type != part_types().end() && type->second.host_connector) return true;
    }
    return false;
}

std::string BoardSpec::serial_port_mcu() const {
    for (const auto& part : parts) {
        const auto type = part_types().find(part.type);
        if (type == part_types().end() || !type->second.host_connector) continue;
        for (const auto& net : nets) {
            bool joins_port = false;
            for (const auto& e : net.endpoints) joins_port = joins_port || e.owner == part.name;
            if (!joins_port) continue;
            for (const auto& e : net.endpoints) {
                if (find_mcu(e.owner) != nullptr) return e.owner;
            }
        }
    }
    return "";
}

const SerialDecl* BoardSpec::find_serial(const std::string& n) const {
    for (const auto& s : serial) {
        if (s.name == n) return &s;
    }
    return nullptr;
}

namespace {

// $ENV, then beside the installed avrbench (<prefix>/bin/avrbench and
// <prefix>/share/avrbench/<data>), then the build tree's folder ("" = none).
std::vector<std::string> standard_dirs(const char* env_var, const char* data, const char* build_tree_dir) {
    std::vector<std::string> dirs;
    if (const char* env = std::getenv(env_var)) dirs.emplace_back(env);
    std::error_code ec;
    const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) dirs.push_back((exe.parent_path().parent_path() / "share" / "avrbench" / data).string());
    if (*build_tree_dir != '\0') dirs.emplace_back(build_tree_dir);
    return dirs;
}

}  // namespace

std::vector<std::string> standard_board_dirs() {
#ifdef AVRBENCH_SOURCE_BOARDS_DIR
    return standard_dirs("AVRBENCH_BOARDS_DIR", "boards", AVRBENCH_SOURCE_BOARDS_DIR);
#else
    return standard_dirs("AVRBENCH_BOARDS_DIR", "boards", "");
#endif
}

std::vector<std::string> standard_bootloader_dirs() {
#ifdef AVRBENCH_BUILD_BOOTLOADERS_DIR
    return standard_dirs("AVRBENCH_BOOTLOADERS_DIR", "bootloaders", AVRBENCH_BUILD_BOOTLOADERS_DIR);
#else
    return standard_dirs("AVRBENCH_BOOTLOADERS_DIR", "bootloaders", "");
#endif
}

std::string find_board_file(const std::string& name_or_path) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(name_or_path, ec)) return name_or_path;
    // There, but a FIFO, a device or a folder: say which.
    if (std::filesystem::exists(name_or_path, ec)) check_input_file(name_or_path, "board file", kMaxBoardFileBytes);
    const bool bare = !name_or_path.empty() && name_or_path.find('/') == std::string::npos &&
                      std::filesystem::path(name_or_path).extension() != ".yaml";
    if (!bare) throw BadInput(name_or_path + ": no such board file");
    for (const auto& dir : standard_board_dirs()) {
        const std::filesystem::path candidate = std::filesystem::path(dir) / (name_or_path + ".yaml");
        if (std::filesystem::is_regular_file(candidate, ec)) return candidate.string();
    }
    throw BadInput(name_or_path + ": no such board file, and no standard board of that name (see docs/BOARDS.md)");
}

BoardSpec load_board_file(const std::string& name_or_path) {
    const std::string path = find_board_file(name_or_path);
    return parse_board_text(read_input_file(path, "board file", kMaxBoardFileBytes), path);
}

std::vector<StandardBoard> list_standard_boards() {
    std::map<std::string, StandardBoard> found;
    for (const auto& dir : standard_board_dirs()) {
        std::error_code ec;
        for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
            const std::filesystem::path& file = entry.path();
            if (file.extension() != ".yaml" || !entry.is_regular_file(ec)) continue;
            const std::string name = file.stem().string();
            if (found.count(name) != 0) continue;  // an earlier folder's board of that name wins
            StandardBoard board{name, file.string(), "", ""};
            try {
                board.description = load_board_file(file.string()).description;
            } catch (const BadInput& e) {
                board.error = e.what();
            }
            found.emplace(name, std::move(board));
        }
    }
    std::vector<StandardBoard> boards;
    for (auto& [name, board] : found) boards.push_back(std::move(board));
    return boards;
}

namespace {

// Replaces the declaration named like `item` in `into`, or appends it.
template <class Decl>
void overlay(std::vector<Decl>& into, Decl item) {
    for (auto& existing : into) {
        if (existing.name == item.name) {
            existing = std::move(item);
            return;
        }
    }
    into.push_back(std::move(item));
}

BoardSpec parse_board(const std::string& text, const std::string& path, int depth);

// A path (absolute, or relative to the board file), or a bare file name
// looked up next to the board file and then in the bench's boot loader
// directories (the ones the build makes, e.g. optiboot_atmega328.hex).
std::string find_bootloader(const std::string& name, const std::string& board_path, const std::string& location) {
    const std::filesystem::path given(name);
    if (given.is_absolute()) return name;
    std::error_code ec;
    const std::filesystem::path beside = std::filesystem::path(board_path).parent_path() / given;
    if (name.find('/') != std::string::npos || std::filesystem::is_regular_file(beside, ec)) return beside.string();
    std::string searched = beside.parent_path().string();
    for (const auto& dir : standard_bootloader_dirs()) {
        const std::filesystem::path candidate = std::filesystem::path(dir) / given;
        if (std::filesystem::is_regular_file(candidate, ec)) return candidate.string();
        searched += ", " + dir;
    }
    throw BadInput(location + ": bootloader '" + name + "' not found (looked in " + searched + ")");
}

// 0xDE or 222.
std::uint8_t parse_byte(const std::string& text, const std::string& what) {
    unsigned value = 0;
    const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
    const char* first = text.data() + (hex ? 2 : 0);
    const char* last = text.data() + text.size();
    const auto [end, ec] = std::from_chars(first, last, value, hex ? 16 : 10);
    if (ec != std::errc() || end != last || first == last || value > 0xFF) {
        throw BadInput(what + " '" + text + "' is not a byte (0x00..0xFF)");
    }
    return static_cast<std::uint8_t>(value);
}

// `fuses: {low: 0xFF, high: 0xDE, extended: 0xFD}`: all three bytes, as
// avrdude's -U lfuse/hfuse/efuse and Arduino's boards.txt give them.
std::array<std::uint8_t, 3> parse_fuses(const YAML::Node& node, const std::string& path, const std::string& what) {
    if (!node.IsMap()) throw BadInput(yaml_where(path, node) + ": " + what + " must be a map {low: 0xFF, high: 0xDE, extended: 0xFD}");
    std::array<std::uint8_t, 3> fuses{};
    std::array<bool, 3> given{};
    static const std::array<std::string, 3> kNames = {"low", "high", "extended"};
    for (const auto& kv : node) {
        const std::string key = kv.first.Scalar();
        const std::string loc = yaml_where(path, kv.first);
        std::size_t index = 0;
        while (index < kNames.size() && kNames[index] != key) ++index;
        if (index == kNames.size()) throw BadInput(loc + ": " + what + ": unknown fuse '" + key + "' (expected low, high, extended)");
        fuses[index] = parse_byte(yaml_scalar(kv.second, path, key), loc + ": " + what + ": " + key);
        given[index] = true;
    }
    for (std::size_t i = 0; i < kNames.size(); ++i) {
        if (!given[i]) throw BadInput(yaml_where(path, node) + ": " + what + ": missing '" + kNames[i] + "' (give low, high and extended)");
    }
    return fuses;
}

// `extends: ramps-1.4`: the base board, a standard board's name or a file
// relative to this one.
BoardSpec load_base(const YAML::Node& node, const std::string& path, int depth) {
    const std::string loc = yaml_where(path, node);
    const std::string name = yaml_scalar(node, path, "extends");
    // Four levels are plenty for variants of variants; more is a loop.
    if (depth >= 4) throw BadInput(loc + ": 'extends' nests more than 4 boards deep (a board that extends itself?)");
    std::string base_path = name;
    const std::filesystem::path relative = std::filesystem::path(path).parent_path() / name;
    std::error_code ec;
    if (name.find('/') != std::string::npos || std::filesystem::path(name).extension() == ".yaml") {
        if (std::filesystem::is_regular_file(relative, ec)) base_path = relative.string();
    }
    std::string file;
    try {
        file = find_board_file(base_path);
    } catch (const BadInput& e) {
        throw BadInput(loc + ": extends " + e.what());
    }
    return parse_board(read_input_file(file, "board file", kMaxBoardFileBytes), file, depth + 1);
}

}  // namespace

BoardSpec parse_board_text(const std::string& text, const std::string& path) {
    try {
        return parse_board(text, path, 0);
    } catch (const YAML::Exception& e) {
        // A node of another shape than the one read (a list where a map
        // belongs, ...) that no check above caught: still the user's file.
        throw BadInput(escaped(path) + ":" + std::to_string(e.mark.line + 1) + ": unexpected YAML here (" + escaped(e.msg) + ")");
    }
}

namespace {

namespace {

// The sections a board file may have, its name and description.
void parse_header(const YAML::Node& root, const std::string& path, BoardSpec& spec) {
    static const std::set<std::string> kSections = {"board", "description", "extends", "mcus",
                                                    "parts", "nets",  "serial",      "labels"};
    for (const auto& kv : root) {
        const std::string key = kv.first.Scalar();
        if (kSections.count(key) == 0) {
            throw BadInput(yaml_where(path, kv.first) + ": unknown section '" + key +
                           "' (expected board, description, extends, mcus, parts, nets, serial, labels)");
        }
    }
    if (root["board"]) {
        // A name people type and the summary prints: letters, digits, '_', '-', '.'.
        spec.name = yaml_scalar(root["board"], path, "board");
        const bool printable_name = !spec.name.empty() && spec.name.size() <= 64 &&
                                    std::all_of(spec.name.begin(), spec.name.end(), [](char c) {
                                        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
                                    });
        if (!printable_name) {
            throw BadInput(yaml_where(path, root["board"]) + ": board name " + quoted_text(spec.name) +
                           " is not 1 to 64 letters, digits, '_', '-' or '.'");
        }
    }
    if (root["description"]) spec.description = yaml_scalar(root["description"], path, "description");

}

void parse_mcus(const YAML::Node& root, const std::string& path, bool has_base, BoardSpec& spec, std::set<std::string>& names) {
    const YAML::Node mcus = root["mcus"];
    if (!has_base && (!mcus || !mcus.IsMap() || mcus.size() == 0)) {
        throw BadInput(path + ":1: the board needs an 'mcus' map with at least one MCU");
    }
    if (mcus && !mcus.IsMap()) throw BadInput(yaml_where(path, mcus) + ": 'mcus' must be a map of MCU name to type and clock");
    if (mcus && mcus.size() > kMaxMcusPerBoard) {
        throw BadInput(yaml_where(path, mcus) + ": " + std::to_string(mcus.size()) + " MCUs; a board holds at most " +
                       std::to_string(kMaxMcusPerBoard) + " (their lockstep costs grow with the square of the count)");
    }
    for (const auto& kv : mcus) {
        McuDecl m;
        m.name = kv.first.Scalar();
        m.location = yaml_where(path, kv.first);
        check_name(m.name, m.location, "MCU", names);
        if (!kv.second.IsMap()) throw BadInput(m.location + ": MCU '" + m.name + "' must be a map with type and clock");
        for (const auto& field : kv.second) {
            const std::string key = field.first.Scalar();
            const std::string loc = yaml_where(path, field.first);
            if (key == "type") m.type = yaml_scalar(field.second, path, "type");
            else if (key == "clock") m.clock_hz = parse_frequency_hz(yaml_scalar(field.second, path, "clock"), loc + ": MCU '" + m.name + "': clock");
            else if (key == "firmware") m.firmware = yaml_scalar(field.second, path, "firmware");
            else if (key == "bootloader") m.bootloader = yaml_scalar(field.second, path, "bootloader");
            else if (key == "fuses") m.fuses = parse_fuses(field.second, path, "MCU '" + m.name + "': fuses");
            else if (key == "lock") m.lock_bits = parse_byte(yaml_scalar(field.second, path, "lock"), loc + ": MCU '" + m.name + "': lock");
            else if (key == "watchdog_resets") {
                const std::string value = yaml_scalar(field.second, path, "watchdog_resets");
                if (value != "expected" && value != "findings") {
                    throw BadInput(loc + ": MCU '" + m.name + "': watchdog_resets '" + value + "' is not expected or findings");
                }
                m.watchdog_resets_expected = value == "expected";
            }
            else throw BadInput(loc + ": MCU '" + m.name + "': unknown key '" + key + "' (expected type, clock, firmware, bootloader, fuses, lock, watchdog_resets)");
        }
        if (!m.bootloader.empty() && !m.fuses) {
            throw BadInput(m.location + ": MCU '" + m.name + "': a bootloader needs its fuses (e.g. fuses: {low: 0xFF, high: 0xDE, extended: 0xFD})");
        }
        if (!m.bootloader.empty()) m.bootloader = find_bootloader(m.bootloader, path, m.location);
        if (m.type.empty()) throw BadInput(m.location + ": MCU '" + m.name + "': missing 'type' (e.g. atmega328p)");
        if (m.clock_hz == 0) throw BadInput(m.location + ": MCU '" + m.name + "': missing 'clock' (e.g. 16MHz)");
        if (!m.firmware.empty() && std::filesystem::path(m.firmware).is_relative()) {
            m.firmware = (std::filesystem::path(path).parent_path() / m.firmware).string();
        }
        spec.mcus.push_back(std::move(m));
    }

}

void parse_parts(const YAML::Node& root, const std::string& path, BoardSpec& spec, std::set<std::string>& names) {
    // An empty section (`parts:` with nothing under it) is a board without parts.
    if (const YAML::Node parts = root["parts"]; parts && !parts.IsNull()) {
        if (!parts.IsMap()) throw BadInput(yaml_where(path, parts) + ": 'parts' must be a map of part name to its settings");
        for (const auto& kv : parts) {
            PartDecl p;
            p.name = kv.first.Scalar();
            p.location = yaml_where(path, kv.first);
            check_name(p.name, p.location, "part", names);
            if (!kv.second.IsMap()) throw BadInput(p.location + ": part '" + p.name + "' must be a map with a type");
            for (const auto& field : kv.second) {
                const std::string key = field.first.Scalar();
                if (key == "type") {
                    p.type = yaml_scalar(field.second, path, "type");
                } else {
                    p.params.push_back({key, yaml_scalar(field.second, path, "parameter " + key), yaml_where(path, field.first),
                                        std::filesystem::path(path).parent_path().string()});
                }
            }
            if (p.type.empty()) throw BadInput(p.location + ": part '" + p.name + "': missing 'type'");
            spec.parts.push_back(std::move(p));
        }
    }

}

void parse_nets(const YAML::Node& root, const std::string& path, BoardSpec& spec) {
    if (const YAML::Node nets = root["nets"]; nets && !nets.IsNull()) {
        if (!nets.IsMap()) throw BadInput(yaml_where(path, nets) + ": 'nets' must be a map of net name to its endpoints");
        std::set<std::string> net_names;
        for (const auto& kv : nets) {
            NetDecl n;
            n.name = kv.first.Scalar();
            n.location = yaml_where(path, kv.first);
            check_name(n.name, n.location, "net", net_names);
            if (!kv.second.IsSequence() || kv.second.size() < 2) {
                throw BadInput(n.location + ": net '" + n.name + "' must list at least two endpoints, e.g. [uno.PD2, x_driver.step]");
            }
            for (const auto& e : kv.second) {
                n.endpoints.push_back(parse_endpoint(e, path));
            }
            spec.nets.push_back(std::move(n));
        }
    }

}

void parse_serial(const YAML::Node& root, const std::string& path, BoardSpec& spec, std::set<std::string>& names) {
    if (const YAML::Node serial = root["serial"]; serial && !serial.IsNull()) {
        if (!serial.IsMap()) throw BadInput(yaml_where(path, serial) + ": 'serial' must be a map of port name to its settings");
        for (const auto& kv : serial) {
            SerialDecl s;
            s.name = kv.first.Scalar();
            s.location = yaml_where(path, kv.first);
            check_name(s.name, s.location, "serial port", names);
            if (!kv.second.IsMap()) {
                throw BadInput(yaml_where(path, kv.second) + ": serial port '" + s.name + "' must be a map {mcu, usart, flow, ...}");
            }
            for (const auto& field : kv.second) {
                const std::string key = field.first.Scalar();
                const std::string loc = yaml_where(path, field.first);
                const std::string value = yaml_scalar(field.second, path, key);
                if (key == "mcu") {
                    s.mcu = value;
                } else if (key == "usart") {
                    // USART0..3: the ATmega2560 has the most (datasheet §22); the board's
                    // MCU is checked to have it when the board is built.
                    s.usart = static_cast<int>(parse_integer(value, loc + ": usart", 0, 3));
                } else if (key == "flow") {
                    if (value != "send_and_wait" && value != "character_counting") {
                        throw BadInput(loc + ": flow '" + value + "' is not send_and_wait or character_counting");
                    }
                    s.flow = value;
                } else if (key == "rx_buffer") {
                    // The firmware's receive buffer: grbl uses 128 (serial.h); no AVR
                    // has more than 64 KiB of RAM to hold one.
                    s.rx_buffer_bytes = static_cast<unsigned>(parse_integer(value, loc + ": rx_buffer", 1, 65536));
                } else if (key == "family") {
                    // The serial_host part's choices (stimulus/HostFamily.hpp).
                    static const std::set<std::string> kFamilies = {"generic", "grbl",     "marlin", "teacup",
                                                                    "repetier", "sprinter", "prusa"};
                    if (kFamilies.count(value) == 0) {
                        throw BadInput(loc + ": family '" + value +
                                       "' is not generic, grbl, marlin, teacup, repetier, sprinter or prusa");
                    }
                    s.family = value;
                } else if (key == "line_timeout") {
                    s.line_timeout_s = seconds_from_ps(parse_duration_ps(value, loc + ": line_timeout"));
                    if (!(s.line_timeout_s >= kShortestLineTimeout_s)) {
                        throw BadInput(loc + ": line_timeout must be at least 100us: no firmware answers faster");
                    }
                } else {
                    throw BadInput(loc + ": serial '" + s.name + "': unknown key '" + key +
                                   "' (expected mcu, usart, flow, rx_buffer, family, line_timeout)");
                }
            }
            spec.serial.push_back(std::move(s));
        }
    }

}

void parse_labels(const YAML::Node& root, const std::string& path, BoardSpec& spec) {
    if (const YAML::Node labels = root["labels"]; labels && !labels.IsNull()) {
        if (!labels.IsMap()) throw BadInput(yaml_where(path, labels) + ": 'labels' must be a map of name to endpoint");
        std::set<std::string> label_names;
        for (const auto& kv : labels) {
            LabelDecl l;
            l.name = kv.first.Scalar();
            l.location = yaml_where(path, kv.first);
            check_name(l.name, l.location, "label", label_names);
            l.endpoint = parse_endpoint(kv.second, path);
            spec.labels.push_back(std::move(l));
        }
    }

}

// A variant: what it names replaces the base's declaration of that name,
// whole; what it adds is added (docs/BOARDS.md, "Variants").
BoardSpec merge_with_base(BoardSpec base_spec, BoardSpec spec, const std::string& path) {
    {
        BoardSpec merged = std::move(base_spec);
        merged.path = path;
        if (!spec.name.empty()) merged.name = spec.name;
        if (!spec.description.empty()) merged.description = spec.description;
        for (auto& m : spec.mcus) overlay(merged.mcus, std::move(m));
        for (auto& p : spec.parts) overlay(merged.parts, std::move(p));
        for (auto& n : spec.nets) overlay(merged.nets, std::move(n));
        for (auto& s2 : spec.serial) overlay(merged.serial, std::move(s2));
        for (auto& l : spec.labels) overlay(merged.labels, std::move(l));
        spec = std::move(merged);
        std::set<std::string> all_names;
        for (const auto& m : spec.mcus) check_name(m.name, m.location, "MCU", all_names);
        for (const auto& p : spec.parts) check_name(p.name, p.location, "part", all_names);
        for (const auto& s2 : spec.serial) check_name(s2.name, s2.location, "serial port", all_names);
        if (spec.mcus.size() > kMaxMcusPerBoard) {
            throw BadInput(escaped(path) + ":1: with its base board, " + std::to_string(spec.mcus.size()) +
                           " MCUs; a board holds at most " + std::to_string(kMaxMcusPerBoard));
        }
    }
    return spec;
}

// Endpoints on one net each, and every reference within the (merged) board resolved.
void check_references(const BoardSpec& spec) {
    std::set<std::string> used_endpoints;
    for (const auto& n : spec.nets) {
        for (const auto& ep : n.endpoints) {
            if (!used_endpoints.insert(ep.text()).second) {
                throw BadInput(ep.location + ": '" + ep.text() + "' is already on another net");
            }
        }
    }

    // Cross-references within the (merged) board.
    auto check_endpoint = [&](const Endpoint& e) {
        if (const McuDecl* m = spec.find_mcu(e.owner)) {
            check_mcu_pin(e, *m);
        } else if (spec.find_part(e.owner) == nullptr) {
            throw BadInput(e.location + ": '" + e.owner + "' is neither an MCU nor a part of this board");
        }
    };
    for (const auto& n : spec.nets) {
        for (const auto& e : n.endpoints) check_endpoint(e);
    }
    for (const auto& l : spec.labels) check_endpoint(l.endpoint);
    for (const auto& s : spec.serial) {
        if (spec.find_mcu(s.mcu) == nullptr) throw BadInput(s.location + ": serial '" + s.name + "': unknown MCU '" + s.mcu + "'");
    }
}

// The `serial:` section of earlier board files, as what it always meant: a
// serial_host part on the USART's TXD and RXD pins (parts/SerialHost.hpp),
// with a deprecation line naming the form that replaces it.
// The deprecation lines to tell once the board has loaded (not before an
// error in it: one line for one problem).
std::vector<std::string> translate_serial_ports(BoardSpec& spec) {
    std::vector<std::string> deprecations;
    for (const SerialDecl& s : spec.serial) {
        const McuDecl& mcu = *spec.find_mcu(s.mcu);  // check_references found it
        const auto pins = usart_pins(mcu.type, s.usart);
        if (!pins) {
            throw BadInput(s.location + ": serial '" + s.name + "': " + mcu.type + " has no USART" + std::to_string(s.usart) +
                           " the bench knows the pins of; declare a serial_host part on its pins (docs/BOARDS.md)");
        }
        const std::string txd = std::string("P") + pins->tx_port + static_cast<char>('0' + pins->tx_bit);
        const std::string rxd = std::string("P") + pins->rx_port + static_cast<char>('0' + pins->rx_bit);
        PartDecl part{s.name, "serial_host", {}, s.location};
        part.params.push_back({"family", s.family, s.location});
        part.params.push_back({"flow", s.flow, s.location});
        part.params.push_back({"rx_buffer", std::to_string(s.rx_buffer_bytes), s.location});
        if (s.line_timeout_s > 0) {
            char timeout[48];
            std::snprintf(timeout, sizeof timeout, "%.17gs", s.line_timeout_s);
            part.params.push_back({"line_timeout", timeout, s.location});
        }
        spec.parts.push_back(std::move(part));
        const std::string rx_net = s.name + "_rx", tx_net = s.name + "_tx";
        for (const auto& n : spec.nets) {
            if (n.name == rx_net || n.name == tx_net) {
                throw BadInput(s.location + ": serial '" + s.name + "' needs the nets " + rx_net + " and " + tx_net + ", and " +
                               n.location + " declares net '" + n.name + "'; declare a serial_host part instead");
            }
        }
        spec.nets.push_back({rx_net, {{mcu.name, txd, s.location}, {s.name, "rx", s.location}}, s.location});
        spec.nets.push_back({tx_net, {{s.name, "tx", s.location}, {mcu.name, rxd, s.location}}, s.location});
        deprecations.push_back(s.location + ": 'serial:' is deprecated; declare the port as a part on the USART's pins: parts: " +
                               s.name + ": {type: serial_host, family: " + s.family + ", flow: " + s.flow + "}, nets: " + rx_net +
                               ": [" + mcu.name + "." + txd + ", " + s.name + ".rx], " + tx_net + ": [" + s.name + ".tx, " +
                               mcu.name + "." + rxd + "] (docs/BOARDS.md)");
    }
    spec.serial.clear();
    return deprecations;
}

}  // namespace

BoardSpec parse_board(const std::string& text, const std::string& path, int depth) {
    const YAML::Node root = load_yaml(text, path);
    if (!root.IsMap()) throw BadInput(escaped(path) + ":1: a board file is a map with mcus, parts, nets");
    BoardSpec spec;
    spec.path = path;
    parse_header(root, path, spec);
    std::optional<BoardSpec> base;
    if (root["extends"]) base = load_base(root["extends"], path, depth);
    std::set<std::string> names;
    parse_mcus(root, path, base.has_value(), spec, names);
    parse_parts(root, path, spec, names);
    parse_nets(root, path, spec);
    parse_serial(root, path, spec, names);
    parse_labels(root, path, spec);
    if (base) spec = merge_with_base(std::move(*base), std::move(spec), path);
    check_references(spec);
    if (depth == 0 && !spec.serial.empty()) {
        const std::vector<std::string> deprecations = translate_serial_ports(spec);
        check_references(spec);
        for (const std::string& line : deprecations) notice(line);
    }
    return spec;
}

}  // namespace

}  // namespace avrbench
