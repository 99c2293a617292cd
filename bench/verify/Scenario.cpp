#include "verify/Scenario.hpp"

#include "core/TextPattern.hpp"

#include "trace/WaveformFiles.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "boards/BoardFile.hpp"
#include "boards/YamlKeys.hpp"
#include "stimulus/HostFamily.hpp"
#include "core/Errors.hpp"
#include "core/VectorNames.hpp"
#include "core/Finding.hpp"
#include "core/InputFile.hpp"
#include "periph/ports/McuPins.hpp"
#include "core/Units.hpp"

namespace fs = std::filesystem;

namespace avrbench {
namespace {

std::string resolve(const std::string& scenario_path, const std::string& relative) {
    if (relative.empty() || fs::path(relative).is_absolute()) return relative;
    return (fs::path(scenario_path).parent_path() / relative).lexically_normal().string();
}

bool parse_level(const std::string& text, const std::string& location) {
    if (text == "0" || text == "low") return false;
    if (text == "1" || text == "high") return true;
    throw BadInput(location + ": level '" + text + "' is not 0/low or 1/high");
}

RuleKind parse_rule(const std::string& text, const std::string& location) {
    for (RuleKind k : {RuleKind::Exact, RuleKind::Timing, RuleKind::Steps, RuleKind::StepRate, RuleKind::PwmDuty,
                       RuleKind::Band, RuleKind::Ignore}) {
        if (text == to_string(k)) return k;
    }
    throw BadInput(location + ": unknown rule '" + text + "' (exact, timing, steps, step-rate, pwm-duty, band, ignore)");
}

// One item of `steps:` or `expect:`: a one-key map whose value is a scalar
// or a map of scalars (or, for `findings`, a list).
struct Item {
    std::string kind;
    std::string location;
    YAML::Node value;
    std::string path;

    bool is_scalar() const { return value.IsScalar(); }
    std::string scalar_value() const {
        if (!value.IsScalar()) throw BadInput(location + ": '" + kind + "' takes a single value here");
        return value.Scalar();
    }
    // Checks that the value is a map with exactly `required` and some of `optional`.
    void expect_keys(const std::set<std::string>& required, const std::set<std::string>& optional = {}) const {
        if (!value.IsMap()) {
            std::string keys;
            for (const auto& k : required) keys += (keys.empty() ? "" : ", ") + k;
            throw BadInput(location + ": '" + kind + "' takes a map {" + keys + "}");
        }
        for (const auto& kv : value) {
            const std::string key = kv.first.Scalar();
            if (required.count(key) == 0 && optional.count(key) == 0) {
                std::string keys;
                for (const auto& k : required) keys += (keys.empty() ? "" : ", ") + k;
                for (const auto& k : optional) keys += (keys.empty() ? "" : ", ") + k;
                throw BadInput(yaml_where(path, kv.first) + ": '" + kind + "' has no key '" + key + "' (keys: " + keys + ")");
            }
            if (!kv.second.IsScalar()) throw BadInput(yaml_where(path, kv.second) + ": " + key + " must be a single value");
        }
        for (const auto& k : required) {
            if (!value[k]) throw BadInput(location + ": '" + kind + "' needs '" + k + "'");
        }
    }
    std::string get(const std::string& key) const { return value[key].Scalar(); }
    std::string at(const std::string& key) const { return yaml_where(path, value[key]); }
    bool has(const std::string& key) const { return value.IsMap() && value[key]; }
};

Item read_item(const YAML::Node& node, const std::string& path, const std::set<std::string>& kinds, const char* what) {
    if (!node.IsMap() || node.size() != 1) throw BadInput(yaml_where(path, node) + ": each " + what + " is one 'kind: value' entry");
    const auto kv = *node.begin();
    Item item{yaml_scalar(kv.first, path, what), yaml_where(path, kv.first), kv.second, path};
    if (kinds.count(item.kind) == 0) {
        std::string list;
        for (const auto& k : kinds) list += (list.empty() ? "" : ", ") + k;
        throw BadInput(item.location + ": unknown " + what + " '" + item.kind + "' (known: " + list + ")");
    }
    if (!kv.second.IsScalar() && !kv.second.IsMap() && !kv.second.IsSequence()) {
        throw BadInput(item.location + ": '" + item.kind + "' needs a value");
    }
    return item;
}

// What the scenario may name on its board, checked against the board file.
class BoardNames {
public:
    explicit BoardNames(const BoardSpec& board) : board_(board) {}

    void check_pin(const std::string& text, const std::string& location) const {
        for (const auto& l : board_.labels) {
            if (l.name == text) return;
        }
        const auto dot = text.find('.');
        if (dot == std::string::npos) {
            throw BadInput(location + ": '" + text + "' is neither mcu.PIN nor a label of " + board_.path + labels());
        }
        const std::string mcu = text.substr(0, dot), pin = text.substr(dot + 1);
        const McuDecl* decl = board_.find_mcu(mcu);
        if (decl == nullptr) throw BadInput(location + ": the board has no MCU '" + mcu + "' (in '" + text + "')");
        std::string p = pin;
        if (p.size() == 3 && (p[0] == 'P' || p[0] == 'p')) p.erase(0, 1);
        const bool ok = p.size() == 2 && std::isalpha(static_cast<unsigned char>(p[0])) && p[1] >= '0' && p[1] <= '7' &&
                        mcu_has_pin(decl->type, static_cast<char>(std::toupper(static_cast<unsigned char>(p[0]))), p[1] - '0');
        if (!ok) throw BadInput(location + ": " + decl->type + " has no pin '" + pin + "' (in '" + text + "')");
    }

    // The type of MCU `name` ("" = the board's first).
    std::string mcu_type(const std::string& name) const {
        const McuDecl* decl = name.empty() ? &board_.mcus.front() : board_.find_mcu(name);
        return decl == nullptr ? "" : decl->type;
    }

    void check_mcu(const std::string& name, const std::string& location) const {
        if (board_.find_mcu(name) != nullptr) return;
        std::string list;
        for (const auto& m : board_.mcus) list += (list.empty() ? "" : ", ") + m.name;
        throw BadInput(location + ": the board has no MCU '" + name + "' (MCUs: " + list + ")");
    }

    void check_part(const std::string& name, const std::string& location) const {
        if (board_.find_part(name) == nullptr) {
            std::string list;
            for (const auto& p : board_.parts) list += (list.empty() ? "" : ", ") + p.name;
            throw BadInput(location + ": the board has no part '" + name + "' (parts: " + (list.empty() ? "none" : list) + ")");
        }
    }

    void check_axis(const std::string& name, const std::string& location) const {
        std::string axes;
        for (const auto& p : board_.parts) {
            if (p.type == "linear_axis" || p.type == "rotary_axis") axes += (axes.empty() ? "" : ", ") + p.name;
        }
        const PartDecl* p = board_.find_part(name);
        if (p == nullptr || (p->type != "linear_axis" && p->type != "rotary_axis")) {
            throw BadInput(location + ": the board has no axis '" + name + "' (axes: " + (axes.empty() ? "none" : axes) + ")");
        }
    }

    // `name`, or (empty) the board's first part of `type`; BadInput naming what there is.
    std::string part_of_type(const std::string& name, const std::string& type, const std::string& location) const {
        if (!name.empty()) {
            check_part(name, location);
            if (board_.find_part(name)->type != type) throw BadInput(location + ": part '" + name + "' is not an " + type);
            return name;
        }
        for (const auto& p : board_.parts) {
            if (p.type == type) return p.name;
        }
        throw BadInput(location + ": the board has no " + type + " part");
    }

    void check_serial(const std::string& kind, const std::string& location) const {
        if (board_.has_serial_port()) return;
        throw BadInput(location + ": '" + kind + "' needs a serial port (a serial_host part), and " + board_.path +
                       " has none");
    }

private:
    std::string labels() const {
        std::string list;
        for (const auto& l : board_.labels) list += (list.empty() ? "" : ", ") + l.name;
        return list.empty() ? "" : " (labels: " + list + ")";
    }
    const BoardSpec& board_;
};

ScenarioStep parse_step(const Item& item, const std::string& path, const BoardNames& names) {
    ScenarioStep step;
    step.kind = item.kind;
    step.location = item.location;
    const std::string& k = item.kind;
    if (k == "send") {
        names.check_serial(k, item.location);
        step.action = SendStep{item.scalar_value()};
    } else if (k == "send_file") {
        names.check_serial(k, item.location);
        const std::string file = resolve(path, item.scalar_value());
        std::error_code ec;
        check_input_file(file, item.location + ": send_file", kMaxGcodeFileBytes);
        step.action = SendFileStep{file};
    } else if (k == "delay") {
        step.action = DelayStep{parse_duration_ps(item.scalar_value(), item.location + ": delay")};
    } else if (k == "wait_idle") {
        step.action = WaitIdleStep{parse_duration_ps(item.scalar_value(), item.location + ": wait_idle")};
    } else if (k == "wait_for_text") {
        names.check_serial(k, item.location);
        step.action = WaitForTextStep{item.scalar_value()};
    } else if (k == "wait_pin" || k == "set_input") {
        item.expect_keys({"pin", "level"});
        names.check_pin(item.get("pin"), item.at("pin"));
        const bool level = parse_level(item.get("level"), item.at("level"));
        if (k == "wait_pin") step.action = WaitPinStep{item.get("pin"), level};
        else step.action = SetInputStep{item.get("pin"), level};
    } else if (k == "release_input") {
        names.check_pin(item.scalar_value(), item.location);
        step.action = ReleaseInputStep{item.scalar_value()};
    } else if (k == "inject_fault") {
        item.expect_keys({"part", "fault"});
        names.check_part(item.get("part"), item.at("part"));
        step.action = InjectFaultStep{item.get("part"), item.get("fault")};
    } else if (k == "press" || k == "release") {
        const std::string part = item.scalar_value();
        names.check_part(part, item.location);
        step.action = PartActionStep{part, k, {}};
    } else if (k == "turn") {
        item.expect_keys({"part", "detents"});
        names.check_part(item.get("part"), item.at("part"));
        const double detents = static_cast<double>(parse_integer(item.get("detents"), item.at("detents") + ": detents", -100000, 100000));
        step.action = PartActionStep{item.get("part"), "turn", {detents}};
    }
    return step;
}

// Counts a scenario can expect: at most 2^53 so a double holds them exactly.
constexpr std::int64_t kMaxCount = std::int64_t{1} << 53;

// isr: {vector, max_cycles, max_latency_cycles, min_runs}, stack:
// {min_headroom_bytes}, interrupts_off: {max_cycles}; each with an optional mcu.
ExpectAction parse_timing_expectation(const Item& item, const BoardNames& names) {
    const std::string& k = item.kind;
    if (!item.value.IsMap()) throw BadInput(item.location + ": '" + k + "' takes a map (docs/SCENARIOS.md)");
    auto mcu = [&]() -> std::string {
        if (!item.has("mcu")) return "";
        names.check_mcu(item.get("mcu"), item.at("mcu"));
        return item.get("mcu");
    };
    auto count = [&](const char* key) {
        return static_cast<std::uint64_t>(parse_integer(item.get(key), item.at(key) + ": " + key, 0, kMaxCount));
    };
    if (k == "isr") {
        item.expect_keys({"vector"}, {"mcu", "max_cycles", "max_latency_cycles", "min_runs"});
        ExpectIsr e;
        e.mcu = mcu();
        const std::string vector = item.get("vector");
        if (!vector.empty() && std::isdigit(static_cast<unsigned char>(vector[0]))) {
            e.vector = static_cast<int>(parse_integer(vector, item.at("vector") + ": vector", 1, 127));
            const std::string type = names.mcu_type(e.mcu);
            if (const auto vectors = vector_count(type); vectors && e.vector >= *vectors) {
                throw BadInput(item.at("vector") + ": the " + type + " has interrupt vectors 1 to " + std::to_string(*vectors - 1) +
                               ", not " + std::to_string(e.vector));
            }
        } else {
            const std::string type = names.mcu_type(e.mcu);
            const auto number = vector_number(type, vector);
            if (!number) {
                throw BadInput(item.at("vector") + ": the " + type + " has no interrupt vector '" + vector +
                               "' (avr-libc's names, e.g. TIMER1_COMPA, or its number)");
            }
            e.vector = *number;
        }
        if (item.has("max_cycles")) e.max_cycles = count("max_cycles");
        if (item.has("max_latency_cycles")) e.max_latency_cycles = count("max_latency_cycles");
        if (item.has("min_runs")) e.min_runs = count("min_runs");
        if (!e.max_cycles && !e.max_latency_cycles && !e.min_runs) {
            throw BadInput(item.location + ": 'isr' needs max_cycles, max_latency_cycles or min_runs");
        }
        return e;
    }
    if (k == "stack") {
        item.expect_keys({"min_headroom_bytes"}, {"mcu"});
        return ExpectStack{mcu(), parse_integer(item.get("min_headroom_bytes"), item.at("min_headroom_bytes") +
                                                                                    ": min_headroom_bytes", 0, 65536)};
    }
    if (k == "cpu") {
        item.expect_keys({"max_busy_percent"}, {"mcu"});
        const double percent = parse_quantity(item.get("max_busy_percent"), Dimension::Dimensionless,
                                              item.at("max_busy_percent") + ": max_busy_percent");
        if (!(percent >= 0 && percent <= 100)) throw BadInput(item.at("max_busy_percent") + ": a percentage, 0 to 100");
        return ExpectCpu{mcu(), percent};
    }
    item.expect_keys({"max_cycles"}, {"mcu"});
    return ExpectInterruptsOff{mcu(), count("max_cycles")};
}

ScenarioExpectation parse_expectation(const Item& item, const BoardNames& names) {
    ScenarioExpectation e;
    e.kind = item.kind;
    e.location = item.location;
    const std::string& k = item.kind;
    if (k == "steps") {
        item.expect_keys({"axis", "count"});
        names.check_axis(item.get("axis"), item.at("axis"));
        e.action = ExpectSteps{item.get("axis"),
                               static_cast<std::uint64_t>(parse_integer(item.get("count"), item.at("count") + ": count", 0, kMaxCount))};
    } else if (k == "position") {
        if (!item.value.IsMap()) throw BadInput(item.location + ": 'position' takes a map {axis, mm or deg, within}");
        const bool deg = item.has("deg");
        item.expect_keys({"axis", deg ? "deg" : "mm"}, {"within"});
        names.check_axis(item.get("axis"), item.at("axis"));
        ExpectPosition p;
        p.axis = item.get("axis");
        const std::string unit = deg ? "deg" : "mm";
        p.value = parse_quantity(item.get(unit), Dimension::Dimensionless, item.at(unit) + ": " + unit);
        if (item.has("within")) {
            p.within = parse_quantity(item.get("within"), Dimension::Dimensionless, item.at("within") + ": within");
            if (p.within < 0) throw BadInput(item.at("within") + ": within must not be negative");
        }
        e.action = p;
    } else if (k == "pin") {
        item.expect_keys({"pin", "level"});
        names.check_pin(item.get("pin"), item.at("pin"));
        e.action = ExpectPin{item.get("pin"), parse_level(item.get("level"), item.at("level"))};
    } else if (k == "text") {
        names.check_serial(k, item.location);
        e.action = ExpectText{item.scalar_value()};
    } else if (k == "signal") {
        item.expect_keys({"name"}, {"min", "max", "from"});
        if (!item.has("min") && !item.has("max")) throw BadInput(item.location + ": 'signal' needs min, max or both");
        ExpectSignal sig;
        const std::string name = item.get("name");
        const auto dot = name.find('.');
        if (dot == std::string::npos || dot == 0 || dot + 1 == name.size()) {
            throw BadInput(item.at("name") + ": '" + name + "' is not PART.SIGNAL (e.g. hotend.block_degC)");
        }
        sig.part = name.substr(0, dot);
        names.check_part(sig.part, item.at("name"));
        sig.signal = name.substr(dot + 1);
        if (item.has("min")) sig.min = parse_quantity(item.get("min"), Dimension::Dimensionless, item.at("min") + ": min");
        if (item.has("max")) sig.max = parse_quantity(item.get("max"), Dimension::Dimensionless, item.at("max") + ": max");
        if (sig.min && sig.max && *sig.min > *sig.max) throw BadInput(item.at("min") + ": min is above max");
        if (item.has("from")) sig.from_ps = parse_duration_ps(item.get("from"), item.at("from") + ": from");
        e.action = sig;
    } else if (k == "lcd_shows") {
        ExpectLcdShows shows;
        if (item.value.IsMap()) {
            item.expect_keys({"pattern"}, {"part", "line"});
            shows.pattern = item.get("pattern");
            if (item.has("line")) shows.line = static_cast<int>(parse_integer(item.get("line"), item.at("line") + ": line", 1, 4));
            shows.part = names.part_of_type(item.has("part") ? item.get("part") : "", "hd44780", item.location);
        } else {
            shows.pattern = item.scalar_value();
            shows.part = names.part_of_type("", "hd44780", item.location);
        }
        TextPattern(shows.pattern, item.location + ": lcd_shows");  // a bad pattern fails when the file loads
        e.action = shows;
    } else if (k == "isr" || k == "stack" || k == "interrupts_off" || k == "cpu") {
        e.action = parse_timing_expectation(item, names);
    } else if (k == "findings") {
        if (item.value.IsSequence()) {
            ExpectFindingKinds kinds;
            std::set<std::string> known;
            for (const FindingKind kind : FindingKind::all()) known.insert(kind.name());
            for (const auto& entry : item.value) {
                const std::string kind = yaml_scalar(entry, item.path, "findings entry");
                if (known.count(kind) == 0) {
                    std::string list;
                    for (const auto& n : known) list += (list.empty() ? "" : ", ") + n;
                    throw BadInput(yaml_where(item.path, entry) + ": unknown finding kind '" + kind + "' (known: " + list + ")");
                }
                kinds.kinds.push_back(kind);
            }
            e.action = kinds;
        } else {
            e.action = ExpectFindingCount{static_cast<std::uint64_t>(
                parse_integer(item.scalar_value(), item.location + ": findings", 0, kMaxCount))};
        }
    }
    return e;
}

std::string checked_name(const std::string& name, const std::string& location) {
    if (name.empty()) throw BadInput(location + ": the scenario name is empty");
    if (name.size() > kMaxScenarioNameBytes) {
        throw BadInput(location + ": the scenario name is " + std::to_string(name.size()) + " bytes long (at most " +
                       std::to_string(kMaxScenarioNameBytes) + ")");
    }
    for (char c : name) {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f || c == '/' || c == '\\') {
            throw BadInput(location + ": the scenario name may not contain '/', '\\' or control characters");
        }
    }
    if (name == "." || name == "..") throw BadInput(location + ": '" + name + "' is not a scenario name");
    return name;
}

}  // namespace

std::vector<std::string> ScenarioSpec::stimulus_files() const {
    std::vector<std::string> out;
    for (const auto& s : steps) {
        if (const auto* f = std::get_if<SendFileStep>(&s.action)) out.push_back(f->path);
    }
    return out;
}

ScenarioSpec load_scenario_checked(const std::string& path, const std::string& firmware_dir);

ScenarioSpec load_scenario(const std::string& path, const std::string& firmware_dir) {
    try {
        return load_scenario_checked(path, firmware_dir);
    } catch (const YAML::Exception& e) {
        // A node of another shape than the one read that no check caught.
        throw BadInput(escaped(path) + ":" + std::to_string(e.mark.line + 1) + ": unexpected YAML here (" + escaped(e.msg) + ")");
    }
}

// The scenario's board: a file beside the scenario (or a path relative to
// it), else a standard board's bare name (`board: arduino-uno`), from
// whatever folder avrbench runs in.
BoardSpec scenario_board(ScenarioSpec& spec, const std::string& path, const std::string& board_value, const YAML::Node& node) {
    std::error_code ec;
    spec.board_path = resolve(path, board_value);
    const bool bare_board = board_value.find('/') == std::string::npos && fs::path(board_value).extension() != ".yaml";
    BoardSpec board;
    try {
        if (bare_board && !fs::is_regular_file(spec.board_path, ec)) spec.board_path = find_board_file(board_value);
        board = load_board_file(spec.board_path);
    } catch (const BadInput& e) {
        // A missing board names the scenario line that points at it.
        if (!fs::is_regular_file(spec.board_path, ec)) throw BadInput(yaml_where(path, node) + ": board " + e.what());
        throw;
    }
    return board;
}

// `firmware: {mcu: name-or-path}`: bare names from firmware_dir; every MCU of the board has one.
void scenario_firmware(ScenarioSpec& spec, const BoardSpec& board, const YAML::Node& root, const std::string& path,
                       const std::string& firmware_dir) {
    std::error_code ec;
    if (!root["firmware"] || !root["firmware"].IsMap()) {
        throw BadInput(path + ":1: the scenario needs 'firmware: {mcu: name-or-path}'");
    }
    for (const auto& kv : root["firmware"]) {
        const std::string mcu = yaml_scalar(kv.first, path, "MCU name");
        if (board.find_mcu(mcu) == nullptr) throw BadInput(yaml_where(path, kv.first) + ": the board has no MCU '" + mcu + "'");
        std::string value = yaml_scalar(kv.second, path, "firmware");
        const bool bare_name = value.find('/') == std::string::npos && value.find(".elf") == std::string::npos;
        value = bare_name ? (fs::path(firmware_dir) / (value + ".elf")).string() : resolve(path, value);
        // A missing file, a device, a FIFO or a folder: one line saying which
        // (ElfImage reads the file itself, with its own bounds).
        check_input_file(value, yaml_where(path, kv.second) + ": firmware", std::numeric_limits<std::uint64_t>::max());
        spec.firmware[mcu] = value;
    }
    for (const auto& m : board.mcus) {
        if (spec.firmware.count(m.name) == 0 && m.firmware.empty()) {
            throw BadInput(yaml_where(path, root["firmware"]) + ": MCU '" + m.name + "' of the board has no firmware");
        }
    }
}

// `host: {family, line_timeout, error_pattern}`.
void scenario_host(ScenarioSpec& spec, const YAML::Node& host, const BoardNames& names, const std::string& path) {
    if (!host.IsMap()) throw BadInput(yaml_where(path, host) + ": 'host' is a map {family, line_timeout, error_pattern}");
    names.check_serial("host", yaml_where(path, host));
    for (const auto& kv : host) {
        const std::string key = yaml_scalar(kv.first, path, "host key");
        const std::string value = yaml_scalar(kv.second, path, key);
        if (key == "family") {
            (void)parse_firmware_family(value, yaml_where(path, kv.second));
            spec.host_family = value;
        } else if (key == "error_pattern") {
            (void)TextPattern(value, yaml_where(path, kv.second) + ": error_pattern");
            spec.host_error_pattern = value;
        } else if (key == "line_timeout") {
            spec.host_line_timeout_ps = parse_duration_ps(value, yaml_where(path, kv.second) + ": line_timeout");
            if (*spec.host_line_timeout_ps == 0) throw BadInput(yaml_where(path, kv.second) + ": line_timeout must be longer than 0");
        } else {
            throw BadInput(yaml_where(path, kv.first) + ": unknown host key '" + key + "' (family, line_timeout, error_pattern)");
        }
    }
}

// One entry of `tolerances:` {signals, rule, cycles, relative, window, band}.
ChannelRule parse_tolerance(const YAML::Node& t, const std::string& path) {
    const std::string loc = yaml_where(path, t);
    if (!t.IsMap()) throw BadInput(loc + ": a tolerance is a map {signals, rule, ...}");
    ChannelRule rule;
    bool has_signals = false;
    for (const auto& kv : t) {
        const std::string key = kv.first.Scalar();
        const std::string value = yaml_scalar(kv.second, path, key);
        const std::string at = yaml_where(path, kv.second) + ": " + key;
        auto non_negative = [&](double v) {
            if (v < 0) throw BadInput(at + ": '" + value + "' must not be negative");
            return v;
        };
        if (key == "signals") {
            rule.pattern = value;
            has_signals = true;
        } else if (key == "rule") {
            rule.kind = parse_rule(value, yaml_where(path, kv.second));
        } else if (key == "cycles") {
            rule.tolerance_cycles = static_cast<double>(parse_integer(value, at, 0, kMaxCount));
        } else if (key == "relative") {
            rule.tolerance_rel = non_negative(parse_quantity(value, Dimension::Dimensionless, at));
        } else if (key == "window") {
            rule.window_s = seconds_from_ps(parse_duration_ps(value, at));
            if (rule.window_s <= 0) throw BadInput(at + ": the window must be longer than 0");
        } else if (key == "band") {
            rule.band = non_negative(parse_quantity(value, Dimension::Dimensionless, at));
        } else {
            throw BadInput(yaml_where(path, kv.first) + ": unknown tolerance key '" + key +
                           "' (signals, rule, cycles, relative, window, band)");
        }
    }
    if (!has_signals) throw BadInput(loc + ": a tolerance needs 'signals' (a glob such as \"uno.PD*\")");
    return rule;
}

ScenarioSpec load_scenario_checked(const std::string& path, const std::string& firmware_dir) {
    const YAML::Node root = load_yaml(read_input_file(path, "scenario", kMaxScenarioFileBytes), path);
    if (!root.IsMap()) throw BadInput(escaped(path) + ":1: a scenario is a map with board, firmware, steps, expect");
    static const std::set<std::string> kKeys = {"name",   "description", "board",  "firmware",       "time_limit", "host",
                                                "steps",  "expect",      "golden", "golden_signals", "tolerances"};
    for (const auto& kv : root) {
        if (kKeys.count(kv.first.Scalar()) == 0) {
            throw BadInput(yaml_where(path, kv.first) + ": unknown key '" + kv.first.Scalar() +
                           "' (expected name, description, board, firmware, time_limit, host, steps, expect, golden, "
                           "golden_signals, tolerances)");
        }
    }
    ScenarioSpec spec;
    spec.path = path;
    spec.name = root["name"] ? checked_name(yaml_scalar(root["name"], path, "name"), yaml_where(path, root["name"]))
                             : checked_name(fs::path(path).stem().string(), path + ":1");
    if (root["description"]) spec.description = yaml_scalar(root["description"], path, "description");
    if (!root["board"]) throw BadInput(path + ":1: the scenario needs 'board'");
    const std::string board_value = yaml_scalar(root["board"], path, "board");
    const BoardSpec board = scenario_board(spec, path, board_value, root["board"]);
    const BoardNames names(board);
    scenario_firmware(spec, board, root, path, firmware_dir);
    if (root["time_limit"]) {
        spec.time_limit_ps = parse_duration_ps(yaml_scalar(root["time_limit"], path, "time_limit"), yaml_where(path, root["time_limit"]) + ": time_limit");
    }
    if (const YAML::Node host = root["host"]) scenario_host(spec, host, names, path);
    auto sequence = [&](const char* key) {
        const YAML::Node node = root[key];
        if (node && !node.IsSequence() && !node.IsNull()) throw BadInput(yaml_where(path, node) + ": '" + key + "' is a list");
        return node;
    };
    static const std::set<std::string> kSteps = {"wait_for_text", "send", "send_file", "wait_idle", "wait_pin",
                                                 "delay", "set_input", "release_input", "inject_fault", "press", "release", "turn"};
    if (const YAML::Node steps = sequence("steps")) {
        for (const auto& node : steps) spec.steps.push_back(parse_step(read_item(node, path, kSteps, "step"), path, names));
    }
    static const std::set<std::string> kExpect = {"steps", "position", "pin", "text", "lcd_shows", "signal", "findings", "isr", "stack", "interrupts_off", "cpu"};
    if (const YAML::Node expect = sequence("expect")) {
        for (const auto& node : expect) spec.expectations.push_back(parse_expectation(read_item(node, path, kExpect, "expectation"), names));
    }
    if (root["golden"]) spec.golden_path = resolve(path, yaml_scalar(root["golden"], path, "golden"));
    if (const YAML::Node globs = sequence("golden_signals")) {
        for (const auto& g : globs) spec.golden_signals.push_back(yaml_scalar(g, path, "golden_signals entry"));
    }
    if (const YAML::Node tolerances = sequence("tolerances")) {
        for (const auto& t : tolerances) spec.tolerances.push_back(parse_tolerance(t, path));
    }
    return spec;
}

std::string ScenarioResult::text() const {
    std::string out = (error ? "ERROR " : passed ? "PASS " : "FAIL ") + name + "\n";
    for (const auto& f : failures) out += "  " + f + "\n";
    if (comparison && !comparison->passed) out += "\n" + comparison->report();
    if (!report_path.empty()) out += "  report: " + report_path + "\n";
    if (!vcd_path.empty()) out += "  waveforms: " + vcd_path + " (gtkwave " + with_extension(vcd_path, ".gtkw") + ")\n";
    return out;
}

ScenarioResult error_result(const std::string& path, const std::string& message) {
    ScenarioResult r;
    r.path = path;
    std::string stem = fs::path(path).stem().string();
    if (stem.empty()) stem = "scenario";
    if (stem.size() > kMaxScenarioNameBytes) stem.resize(kMaxScenarioNameBytes);
    r.name = stem;
    r.error = true;
    r.failures.push_back(message);
    return r;
}

}  // namespace avrbench
