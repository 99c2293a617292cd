// The `avrbench` Python module's native part (`avrbench._avrbench`): the
// library's Bench as Python objects, for tests written in pytest. A front
// end like the CLI: it runs the library's run and adds nothing to it;
// python/avrbench/__init__.py is the pure-Python face (docs/PYTHON.md).
//
// Simulated time only: every wait is bounded by simulated time (a timeout
// the caller gives), and the GIL is released while the simulation runs.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "mcu/Lockstep.hpp"
#include "mcu/Mcu.hpp"
#include "mcu/TimingProfile.hpp"
#include "core/OutputFile.hpp"
#include "core/TextPattern.hpp"
#include "core/Units.hpp"
#include "core/UserStop.hpp"
#include "parts/Part.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/TimelineText.hpp"
#include "trace/WaveformFiles.hpp"
#include "core/Notice.hpp"
#include "run/Bench.hpp"
#include "wiring/Net.hpp"

namespace py = pybind11;

namespace avrbench {
namespace {

// A wait whose simulated-time bound passed (avrbench.Timeout).
class Timeout : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A duration as Python gives it: "250ms" (the CLI's units) or seconds.
Picoseconds duration_ps(const py::object& value, const char* what) {
    if (py::isinstance<py::str>(value)) return parse_duration_ps(value.cast<std::string>(), what);
    if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
        const double s = value.cast<double>();
        if (!(s >= 0 && s <= 1e6)) throw BadInput(std::string(what) + ": seconds from 0 to 10^6");
        return static_cast<Picoseconds>(s * 1e12 + 0.5);
    }
    throw BadInput(std::string(what) + ": a duration like \"250ms\" or a number of seconds");
}

// Ctrl-C while the simulation runs with the GIL released: the interpreter's
// SIGINT handler only marks the signal; the run loops poll
// (core/UserStop.hpp) and, in the main thread, let Python run its handler.
// The KeyboardInterrupt it raises is kept here and raised when the call
// returns (within 20 ms of wall time, plus the slice running then).
struct PendingPythonError {
    PyObject* type = nullptr;
    PyObject* value = nullptr;
    PyObject* traceback = nullptr;
};
PendingPythonError g_interrupt;

bool python_signal_pending() {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return false;
    PyErr_Fetch(&g_interrupt.type, &g_interrupt.value, &g_interrupt.traceback);
    return true;
}

// One call that runs the simulation, interruptible by Ctrl-C. Made with the
// GIL held; raise_if_interrupted() after the run (GIL held again).
class InterruptibleRun {
public:
    InterruptibleRun() {
        clear_user_stop();
        set_user_stop_poll(&python_signal_pending);
    }
    ~InterruptibleRun() {
        set_user_stop_poll(nullptr);
        clear_user_stop();
    }
    InterruptibleRun(const InterruptibleRun&) = delete;
    InterruptibleRun& operator=(const InterruptibleRun&) = delete;
    void raise_if_interrupted() {
        if (g_interrupt.type == nullptr) return;
        PyErr_Restore(g_interrupt.type, g_interrupt.value, g_interrupt.traceback);
        g_interrupt = {};
        throw py::error_already_set();
    }
};

// A recorded signal by the names people use: "scope.name" (uno.PB5,
// x.position_mm, nets.x_step), or a net's or label's name alone (x_step,
// led). -1 when none.
long find_signal(const Timeline& t, const std::string& signal) {
    const auto dot = signal.find('.');
    if (dot != std::string::npos) {
        const std::string scope = signal.substr(0, dot), name = signal.substr(dot + 1);
        if (const long id = t.find(scope, name); id >= 0) return id;
        for (const SignalAlias& a : t.aliases()) {
            if (a.scope == scope && a.name == name) return static_cast<long>(a.target);
        }
        return -1;
    }
    for (const char* scope : {"nets", "labels"}) {
        for (const SignalAlias& a : t.aliases()) {
            if (a.scope == scope && a.name == signal) return static_cast<long>(a.target);
        }
    }
    return -1;
}

class PyBench;

// A serial port of the board: raw bytes in, lines out, read as the firmware
// sends them (a cursor into what it transmitted).
class PySerial {
public:
    PySerial(PyBench& bench, std::string port) : bench_(bench), port_(std::move(port)) {}
    void write(const py::bytes& data);
    std::string read_line(const py::object& timeout);
    std::string expect(const std::string& pattern, const py::object& timeout);
    // The board's G-code host on this port streams the file (`family`,
    // `flow`: overrides of the port's declaration, as run --family/--flow).
    void stream_gcode(const std::string& path, const std::string& family, const std::string& flow);
    std::string received() const;

private:
    PyBench& bench_;
    std::string port_;
    std::size_t cursor_ = 0;   // the first byte of the next line
    std::size_t scanned_ = 0;  // bytes looked at for its end
};

class PyBench {
public:
    PyBench(const std::string& board, std::map<std::string, std::string> firmware, std::string vcd, std::string report,
            bool profile, std::size_t max_events)
        : vcd_(std::move(vcd)), report_(std::move(report)) {
        BoardSpec spec = load_board_file(board);
        // "" is the board's first MCU (Bench(board, "fw.elf") in Python).
        if (auto first = firmware.extract(""); !first.empty()) firmware[spec.mcus.front().name] = first.mapped();
        // The CLI's rules for the files a run reads and writes: every output
        // a file of its own, none of them an input (a VCD over the firmware).
        RunFiles files;
        files.input(spec.path, "the board file");
        for (const auto& [mcu, elf] : firmware) files.input(elf, "the firmware of " + mcu);
        for (const auto& m : spec.mcus) {
            files.input(m.bootloader, "an input of the board");
            if (!m.firmware.empty() && firmware.count(m.name) == 0) files.input(m.firmware, "the firmware of " + m.name);
        }
        if (!vcd_.empty()) {
            files.output(vcd_, "vcd");
            files.output(with_extension(vcd_, ".gtkw"), "vcd's gtkwave save file");
        }
        if (!report_.empty()) files.output(report_, "report");
        files.check();
        bench_ = std::make_unique<Bench>(std::move(spec), firmware);
        if (max_events != 0) bench_->timeline().set_max_held_events(max_events);
        bench_->trace_board();
        if (profile) {
            for (Mcu* m : bench_->board().mcus()) m->enable_profile();
        }
    }
    // BadInput once close() ran: a closed Bench runs nothing and reads nothing.
    Bench& bench() {
        if (closed_) throw BadInput("this Bench is closed (close() or the end of its `with` block); make a new one");
        return *bench_;
    }
    bool closed() const { return closed_; }

    void run_for(const py::object& duration) {
        const Picoseconds end = add_ps(bench().now_ps(), duration_ps(duration, "run_for"));
        InterruptibleRun run;
        {
            py::gil_scoped_release release;
            run_to(end);
        }
        run.raise_if_interrupted();
        check_recorder();
    }
    // Runs in slices of `step` until `predicate()` is true; Timeout after `timeout`.
    void run_until(const py::function& predicate, const py::object& timeout, const py::object& step) {
        const Picoseconds end = add_ps(bench().now_ps(), duration_ps(timeout, "timeout"));
        const Picoseconds slice = std::max<Picoseconds>(1, duration_ps(step, "step"));
        InterruptibleRun run;
        for (;;) {
            if (predicate().cast<bool>()) return;
            if (bench_->now_ps() >= end) throw Timeout("run_until: the condition did not hold within the timeout");
            {
                py::gil_scoped_release release;
                run_to(std::min(end, add_ps(bench_->now_ps(), slice)));
            }
            run.raise_if_interrupted();
            check_recorder();
        }
    }
    std::string run_until_idle(const py::object& max, const py::object& settle) {
        const Picoseconds max_ps = duration_ps(max, "max"), settle_ps = duration_ps(settle, "settle");
        Bench& b = bench();
        IdleResult r;
        InterruptibleRun run;
        {
            py::gil_scoped_release release;
            r = b.run_until_idle_ps(max_ps, settle_ps);
        }
        run.raise_if_interrupted();
        check_recorder();
        return to_string(r);
    }
    bool run_until_sleep(const std::string& mcu, const py::object& timeout) {
        Mcu& m = bench().mcu(mcu);
        const Cycle end = m.cycle() + m.cycles_from_seconds(seconds_from_ps(duration_ps(timeout, "timeout")));
        InterruptibleRun run;
        bool slept = false;
        {
            py::gil_scoped_release release;
            slept = m.run_until_sleep(end);
        }
        run.raise_if_interrupted();
        return slept;
    }
    double now() { return bench().now_seconds(); }

    std::vector<Finding> findings() { return bench().findings(); }

    // The names timeline() takes: every recorded signal as "scope.name"
    // ("uno.PB5", "nets.x_step", "x.position_mm"), aliases included.
    std::vector<std::string> signal_names() {
        std::vector<std::string> names;
        const Timeline& t = bench().timeline();
        for (const SignalInfo& info : t.signals()) names.push_back(info.scope + "." + info.name);
        for (const auto& alias : t.aliases()) names.push_back(alias.scope + "." + alias.name);
        return names;
    }

    // (cycles, values) of one recorded signal: "scope.name", or a net's,
    // label's or part signal's name alone when it is one (x_step, led).
    py::tuple timeline(const std::string& signal) {
        const Timeline& t = bench().timeline();
        const long id = find_signal(t, signal);
        if (id < 0) {
            throw BadInput("timeline: no recorded signal '" + signal + "' (a net or label name, or scope.name such as uno.PB5; "
                           "timeline_signals lists them)");
        }
        const SignalInfo& info = t.signals()[static_cast<std::size_t>(id)];
        std::vector<std::uint64_t> cycles;
        std::vector<double> values;
        for (const TimelineEvent& e : t.events()) {
            if (e.signal != static_cast<SignalId>(id)) continue;
            cycles.push_back(e.cycle);
            values.push_back(info.kind == SignalKind::Real ? e.value.real : static_cast<double>(e.value.bits));
        }
        return py::make_tuple(py::array_t<std::uint64_t>(static_cast<py::ssize_t>(cycles.size()), cycles.data()),
                              py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data()));
    }
    // The timeline in the golden format (trace/TimelineText.hpp), no inputs listed.
    std::string timeline_text() {
        Bench& b = bench();
        TimelineHeader header;
        header.bench_version = AVRBENCH_VERSION;
        header.end_cycle = b.mcu().cycle();
        header.end_clock_hz = b.mcu().frequency_hz();
        return format_timeline_text(b.timeline(), header);
    }
    std::string profile_json(const std::string& mcu) {
        const TimingProfiler* p = bench().mcu(mcu).profile();
        if (p == nullptr) throw BadInput("profile: make the Bench with profile=True");
        return p->json();
    }

    // Writes the VCD and the report asked for (unless `write` is false);
    // afterwards the Bench refuses every call (BadInput).
    void close(bool write) {
        if (closed_) return;
        closed_ = true;
        if (!write) return;
        if (!vcd_.empty()) {
            std::vector<std::string> scopes;
            for (Mcu* m : bench_->board().mcus()) scopes.push_back(m->name());
            WaveformFiles files(bench_->timeline(), vcd_, false, {}, scopes);
            files.finish(bench_->mcu().cycle(), bench_->mcu().frequency_hz());
        }
        if (!report_.empty()) {
            write_html_report(bench_->make_report(bench_->mcu().elf().path() + " on " + bench_->board().spec().name), report_);
        }
    }
    PySerial& serial(const std::string& port) {
        bench().serial_port(port);  // BadInput for an unknown port
        auto& s = serials_[port];
        if (!s) s = std::make_unique<PySerial>(*this, port);
        return *s;
    }

    // Runs to `end` in slices of at most 10 ms simulated, so a Ctrl-C or the
    // recorder's cap ends it at the next slice; with the GIL released.
    void run_to(Picoseconds end) {
        while (bench_->now_ps() < end && !user_stop_requested() && !bench_->timeline().overflowed()) {
            const Picoseconds slice_end = std::min(end, add_ps(bench_->now_ps(), 10 * kPsPerMs));
            if (bench_->board().run_until_ps(slice_end) == StopReason::Halted) break;
        }
    }
    // The CLI's rule: a run whose timeline reached its cap is an error, not
    // a quietly shortened record.
    void check_recorder() {
        if (bench_->timeline().overflowed()) throw BadInput(bench_->timeline().overflow_message());
    }

private:
    std::unique_ptr<Bench> bench_;
    std::string vcd_, report_;
    bool closed_ = false;
    std::map<std::string, std::unique_ptr<PySerial>> serials_;
};

// Lines written here are lines the firmware must answer before
// run_until_idle calls the run done (Bench::write).
void PySerial::write(const py::bytes& data) { bench_.bench().write(port_, std::string(data)); }

std::string PySerial::received() const { return bench_.bench().serial(port_).transmitted_text(); }

std::string PySerial::read_line(const py::object& timeout) {
    Bench& b = bench_.bench();
    const Picoseconds end = add_ps(b.now_ps(), duration_ps(timeout, "timeout"));
    InterruptibleRun run;
    for (;;) {
        // From where the last line ended: each byte is looked at once.
        const std::vector<UartByte>& bytes = b.serial(port_).transmitted();
        for (std::size_t i = scanned_; i < bytes.size(); ++i) {
            if (bytes[i].value != '\n') continue;
            std::string line;
            line.reserve(i - cursor_);
            for (std::size_t k = cursor_; k < i; ++k) line.push_back(static_cast<char>(bytes[k].value));
            cursor_ = scanned_ = i + 1;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            return line;
        }
        scanned_ = bytes.size();
        if (b.now_ps() >= end) throw Timeout("serial " + (port_.empty() ? std::string("(first)") : port_) + ": no line within the timeout");
        {
            py::gil_scoped_release release;
            bench_.run_to(std::min(end, add_ps(b.now_ps(), kPsPerMs)));
        }
        run.raise_if_interrupted();
    }
}

std::string PySerial::expect(const std::string& pattern, const py::object& timeout) {
    // RE2 (core/TextPattern.hpp): linear in the line, no recursion, so a
    // 200 kB line and a pattern such as (a|a)*b are safe.
    const TextPattern re(pattern, "expect");
    Bench& b = bench_.bench();
    const Picoseconds end = add_ps(b.now_ps(), duration_ps(timeout, "timeout"));
    for (;;) {
        const Picoseconds left = end - std::min(end, b.now_ps());
        std::string line;
        try {
            line = read_line(py::float_(seconds_from_ps(left)));
        } catch (const Timeout&) {
            throw Timeout("serial " + (port_.empty() ? std::string("(first)") : port_) + ": no line matching '" +
                          pattern + "' within the timeout");
        }
        if (re.found_in(line)) return line;
    }
}

void PySerial::stream_gcode(const std::string& path, const std::string& family, const std::string& flow) {
    UartHostOptions o = default_host_options(bench_.bench().serial_port(port_));
    if (!family.empty()) o.family = parse_firmware_family(family, "family");
    if (!flow.empty()) o.flow = parse_flow_control(flow, "flow");
    bench_.bench().host(port_, o).load_file(path);
}

// A readout is a count (steps, moves judged) or a measure: a whole number
// comes back as a Python int, so `part.steps == 100` reads as it should.
py::object readout_value(double v) {
    if (std::isfinite(v) && v == std::floor(v) && std::abs(v) < 9007199254740992.0) {
        return py::int_(static_cast<long long>(v));
    }
    return py::float_(v);
}

// A part: every signal it declares as an attribute, its faults as controls.
py::dict part_signals(Part& p) {
    py::dict d;
    for (std::size_t i = 0; i < p.signals().size(); ++i) d[py::str(p.signals()[i].name)] = p.signal_value(i);
    return d;
}

}  // namespace

// The Python classes, one function each.
void bind_finding(py::module_& m) {
    py::class_<Finding>(m, "Finding")
        .def_property_readonly("kind", [](const Finding& f) { return f.kind.name(); })
        .def_property_readonly("severity", [](const Finding& f) { return std::string(to_string(f.kind.severity())); })
        .def_readonly("source", &Finding::source)
        .def_readonly("cycle", &Finding::cycle)
        .def_property_readonly("seconds", [](const Finding& f) { return f.clock_hz ? static_cast<double>(f.cycle) / f.clock_hz : 0.0; })
        .def_property_readonly("pc", [](const Finding& f) -> py::object { return f.has_pc ? py::object(py::int_(f.pc_bytes)) : py::object(py::none()); })
        .def_readonly("symbol", &Finding::symbol)
        .def_readonly("detail", &Finding::detail)
        .def("__str__", &Finding::describe)
        .def("__repr__", [](const Finding& f) { return "<avrbench.Finding " + f.describe() + ">"; });
}

void bind_mcu(py::module_& m) {
    py::class_<Mcu, std::unique_ptr<Mcu, py::nodelete>>(m, "Mcu")
        .def_property_readonly("name", &Mcu::name)
        .def_property_readonly("type", &Mcu::mcu_type)
        .def_property_readonly("frequency_hz", &Mcu::frequency_hz)
        .def_property_readonly("cycle", &Mcu::cycle)
        .def_property_readonly("seconds", &Mcu::seconds)
        .def_property_readonly("pc", &Mcu::pc_bytes)
        .def_property_readonly("sp", &Mcu::stack_pointer)
        .def_property_readonly("sleeping", &Mcu::sleeping)
        .def_property_readonly("halted", &Mcu::halted)
        .def("read", [](const Mcu& mcu, const std::string& symbol, std::size_t size) {
                 const auto bytes = mcu.read_ram(symbol, size);
                 return py::bytes(reinterpret_cast<const char*>(bytes.data()), bytes.size());
             }, py::arg("symbol"), py::arg("size"))
        .def("symbol", [](const Mcu& mcu, const std::string& symbol, std::optional<std::size_t> size_given, bool is_signed) {
                 // The ELF's own size of the object by default; a size past it would read its neighbour.
                 const auto elf_size = mcu.elf().object_size(symbol);
                 std::size_t size = size_given.value_or(elf_size.value_or(1));
                 if (size != 1 && size != 2 && size != 4) {
                     throw BadInput("symbol: " + symbol + " is " + std::to_string(size) + " bytes; give size=1, 2 or 4 (or read() its bytes)");
                 }
                 if (elf_size && size > *elf_size) {
                     throw BadInput("symbol: " + symbol + " is " + std::to_string(*elf_size) + " byte" + (*elf_size == 1 ? "" : "s") +
                                    " in the ELF; size=" + std::to_string(size) + " would read past it");
                 }
                 const auto bytes = mcu.read_ram(symbol, size);
                 std::uint32_t v = 0;
                 for (std::size_t i = size; i-- > 0;) v = (v << 8) | bytes[i];
                 if (!is_signed) return static_cast<std::int64_t>(v);
                 const std::uint32_t sign = 1u << (8 * size - 1);
                 return static_cast<std::int64_t>(v & sign ? static_cast<std::int64_t>(v) - (static_cast<std::int64_t>(sign) << 1)
                                                           : static_cast<std::int64_t>(v));
             }, py::arg("name"), py::arg("size") = py::none(), py::arg("signed") = false,
             "a little-endian variable: its size from the ELF's symbol table (or size=1, 2, 4), unsigned unless signed=True "
             "(the symbol table has no type; the sign is the caller's)")
        .def("write", [](Mcu& mcu, const std::string& symbol, const py::bytes& data) {
                 const std::string bytes = data;
                 mcu.read_ram(symbol, bytes.size());  // BadInput past RAM or for an unknown symbol
                 const auto at = mcu.elf().symbol_address(symbol);
                 for (std::size_t i = 0; i < bytes.size(); ++i) {
                     mcu.poke(static_cast<std::uint32_t>(*at - 0x800000 + i), static_cast<std::uint8_t>(bytes[i]));
                 }
             }, py::arg("symbol"), py::arg("data"));
}

void bind_part(py::module_& m) {
    py::class_<Part, std::unique_ptr<Part, py::nodelete>>(m, "Part")
        .def_property_readonly("name", &Part::name)
        .def_property_readonly("signals", [](Part& p) { return part_signals(p); })
        .def_property_readonly("faults", &Part::fault_names)
        .def_property_readonly("fault", &Part::fault)
        .def("inject_fault", [](Part& p, const std::string& fault) { p.inject_fault(fault, p.clock().cycle()); })
        .def_property_readonly("actions", [](Part& p) {
            std::vector<std::string> names;
            for (const auto& a : p.actions()) names.push_back(a.name);
            return names;
        })
        .def("act", [](Part& p, const std::string& action, const std::vector<double>& arguments) { p.act(action, arguments); },
             py::arg("action"), py::arg("arguments"))
        .def_property_readonly("readouts", [](Part& p) {
            py::dict d;
            for (const auto& r : p.readouts()) d[py::str(r.name)] = readout_value(r.value());
            return d;
        })
        .def("signal", [](Part& p, const std::string& name) {
            if (const auto i = p.signal_index(name)) return py::object(py::float_(p.signal_value(*i)));
            if (const auto* r = p.find_readout(name)) return readout_value(r->value());
            // Text (an LCD's): `lines` as a list of str, `text` the lines joined with newlines.
            if (const auto* t = p.find_text_readout(name)) return py::object(py::cast(t->lines()));
            if (name == "text") {
                if (const auto* t = p.find_text_readout("lines")) {
                    std::string joined;
                    for (const auto& l : t->lines()) joined += (joined.empty() ? "" : "\n") + l;
                    return py::object(py::str(joined));
                }
            }
            std::string names;
            for (const auto& s : p.signals()) names += (names.empty() ? "" : ", ") + s.name;
            for (const auto& r : p.readouts()) names += (names.empty() ? "" : ", ") + r.name;
            for (const auto& t : p.text_readouts()) names += (names.empty() ? "" : ", ") + t.name + (t.name == "lines" ? ", text" : "");
            throw BadInput("part " + p.name() + " has no signal '" + name + "' (it has " + (names.empty() ? "none" : names) + ")");
        });
}

void bind_serial(py::module_& m) {
    py::class_<PySerial>(m, "Serial")
        .def("write", &PySerial::write)
        .def("read_line", &PySerial::read_line, py::arg("timeout") = py::str("1s"))
        .def("expect", &PySerial::expect, py::arg("pattern"), py::arg("timeout") = py::str("1s"))
        .def("stream_gcode", &PySerial::stream_gcode, py::arg("path"), py::arg("family") = "", py::arg("flow") = "")
        .def_property_readonly("received", &PySerial::received);
}

void bind_bench(py::module_& m) {
    py::class_<PyBench>(m, "Bench")
        .def(py::init<const std::string&, std::map<std::string, std::string>, std::string, std::string, bool, std::size_t>(),
             py::arg("board"), py::arg("firmware"), py::arg("vcd") = "", py::arg("report") = "", py::arg("profile") = false,
             py::arg("max_events") = 0)
        .def("run_for", &PyBench::run_for)
        .def("run_until", &PyBench::run_until, py::arg("predicate"), py::arg("timeout"), py::arg("step"))
        .def("run_until_idle", &PyBench::run_until_idle, py::arg("max"), py::arg("settle"))
        .def_property_readonly("left_going", [](PyBench& b) { return b.bench().left_going(); })
        .def_property_readonly("closed", &PyBench::closed)
        .def_property_readonly("timeline_signals", &PyBench::signal_names)
        .def("run_until_sleep", &PyBench::run_until_sleep, py::arg("mcu"), py::arg("timeout"))
        .def_property_readonly("now", &PyBench::now)
        .def("mcu", [](PyBench& b, const std::string& name) { return &b.bench().mcu(name); },
             py::return_value_policy::reference_internal)
        .def_property_readonly("mcus", [](PyBench& b) {
            std::vector<std::string> names;
            for (Mcu* mcu : b.bench().board().mcus()) names.push_back(mcu->name());
            return names;
        })
        .def("part", [](PyBench& b, const std::string& name) { return &b.bench().board().part(name); },
             py::return_value_policy::reference_internal)
        .def_property_readonly("parts", [](PyBench& b) {
            std::vector<std::string> names;
            for (Part* p : b.bench().board().parts()) names.push_back(p->name());
            return names;
        })
        .def("level", [](PyBench& b, const std::string& name) {
            for (const auto& net : b.bench().board().nets()) {
                if (net->name() == name) return net->level();
            }
            return b.bench().board().pin(name).level();
        })
        .def("drive", [](PyBench& b, const std::string& name, bool level) { b.bench().board().drive_pin(name, level); })
        .def("release", [](PyBench& b, const std::string& name) { b.bench().board().release_pin(name); })
        .def("serial", &PyBench::serial, py::arg("port") = "", py::return_value_policy::reference_internal)
        .def_property_readonly("findings", &PyBench::findings)
        .def("timeline", &PyBench::timeline)
        .def("timeline_text", &PyBench::timeline_text)
        .def("profile_json", &PyBench::profile_json)
        .def("close", &PyBench::close, py::arg("write") = true);
}

}  // namespace avrbench

PYBIND11_MODULE(_avrbench, m) {
    using namespace avrbench;
    m.doc() = "avrbench's library for Python (docs/PYTHON.md); use the avrbench package, not this module";
    // A deprecated board-file form and the like: Python warnings, which the
    // caller's filters may silence or turn into errors.
    set_notice_sink([](const std::string& line) {
        py::gil_scoped_acquire gil;  // boards load with the GIL held today; a notice must not depend on it
        if (PyErr_WarnEx(PyExc_DeprecationWarning, line.c_str(), 1) < 0) throw py::error_already_set();
    });
    // avrbench.Error, and below it the CLI's exit codes 2 and 3.
    static py::exception<std::runtime_error> error(m, "Error");  // NOLINT: one per module
    static py::exception<BadInput> bad_input(m, "BadInput", error.ptr());
    static py::exception<Timeout> timeout(m, "Timeout", error.ptr());
    for (PyObject* type : {error.ptr(), bad_input.ptr(), timeout.ptr()}) {
        py::setattr(py::handle(type), "__module__", py::str("avrbench"));
    }
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Timeout& e) {
            PyErr_SetString(timeout.ptr(), e.what());
        } catch (const BadInput& e) {
            PyErr_SetString(bad_input.ptr(), e.what());
        }
    });

    avrbench::bind_finding(m);
    avrbench::bind_mcu(m);
    avrbench::bind_part(m);
    avrbench::bind_serial(m);
    avrbench::bind_bench(m);
}
