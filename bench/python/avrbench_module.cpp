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

#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "boards/BoardFile.hpp"
#include "core/Errors.hpp"
#include "core/Lockstep.hpp"
#include "core/Mcu.hpp"
#include "core/TimingProfile.hpp"
#include "core/Units.hpp"
#include "parts/Part.hpp"
#include "trace/HtmlReport.hpp"
#include "trace/TimelineText.hpp"
#include "trace/WaveformFiles.hpp"
#include "core/Notice.hpp"
#include "verify/Bench.hpp"
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
    std::size_t cursor_ = 0;
};

class PyBench {
public:
    PyBench(const std::string& board, std::map<std::string, std::string> firmware, std::string vcd, std::string report,
            bool profile)
        : vcd_(std::move(vcd)), report_(std::move(report)) {
        BoardSpec spec = load_board_file(board);
        // "" is the board's first MCU (Bench(board, "fw.elf") in Python).
        if (auto first = firmware.extract(""); !first.empty()) firmware[spec.mcus.front().name] = first.mapped();
        bench_ = std::make_unique<Bench>(std::move(spec), firmware);
        bench_->trace_board();
        if (profile) {
            for (Mcu* m : bench_->board().mcus()) m->enable_profile();
        }
    }
    Bench& bench() { return *bench_; }

    void run_for(const py::object& duration) {
        const Picoseconds end = add_ps(bench_->now_ps(), duration_ps(duration, "run_for"));
        py::gil_scoped_release release;
        run_to(end);
    }
    // Runs in slices of `step` until `predicate()` is true; Timeout after `timeout`.
    void run_until(const py::function& predicate, const py::object& timeout, const py::object& step) {
        const Picoseconds end = add_ps(bench_->now_ps(), duration_ps(timeout, "timeout"));
        const Picoseconds slice = std::max<Picoseconds>(1, duration_ps(step, "step"));
        for (;;) {
            if (predicate().cast<bool>()) return;
            if (bench_->now_ps() >= end) throw Timeout("run_until: the condition did not hold within the timeout");
            {
                py::gil_scoped_release release;
                run_to(std::min(end, add_ps(bench_->now_ps(), slice)));
            }
        }
    }
    std::string run_until_idle(const py::object& max, const py::object& settle) {
        const Picoseconds max_ps = duration_ps(max, "max"), settle_ps = duration_ps(settle, "settle");
        IdleResult r;
        {
            py::gil_scoped_release release;
            r = bench_->run_until_idle_ps(max_ps, settle_ps);
        }
        return to_string(r);
    }
    bool run_until_sleep(const std::string& mcu, const py::object& timeout) {
        Mcu& m = bench_->mcu(mcu);
        const Cycle end = m.cycle() + m.cycles_from_seconds(seconds_from_ps(duration_ps(timeout, "timeout")));
        py::gil_scoped_release release;
        return m.run_until_sleep(end);
    }
    double now() const { return bench_->now_seconds(); }

    std::vector<Finding> findings() const { return bench_->findings(); }

    // (cycles, values) of one recorded signal, "scope.name".
    py::tuple timeline(const std::string& signal) const {
        const auto dot = signal.find('.');
        const long id = dot == std::string::npos ? -1 : bench_->timeline().find(signal.substr(0, dot), signal.substr(dot + 1));
        if (id < 0) throw BadInput("timeline: no recorded signal '" + signal + "' (scope.name, e.g. uno.PB5)");
        const SignalInfo& info = bench_->timeline().signals()[static_cast<std::size_t>(id)];
        std::vector<std::uint64_t> cycles;
        std::vector<double> values;
        for (const TimelineEvent& e : bench_->timeline().events()) {
            if (e.signal != static_cast<SignalId>(id)) continue;
            cycles.push_back(e.cycle);
            values.push_back(info.kind == SignalKind::Real ? e.value.real : static_cast<double>(e.value.bits));
        }
        return py::make_tuple(py::array_t<std::uint64_t>(static_cast<py::ssize_t>(cycles.size()), cycles.data()),
                              py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data()));
    }
    // The timeline in the golden format (trace/TimelineText.hpp), no inputs listed.
    std::string timeline_text() const {
        TimelineHeader header;
        header.bench_version = AVRBENCH_VERSION;
        header.end_cycle = bench_->mcu().cycle();
        header.end_clock_hz = bench_->mcu().frequency_hz();
        return format_timeline_text(bench_->timeline(), header);
    }
    std::string profile_json(const std::string& mcu) {
        const TimingProfiler* p = bench_->mcu(mcu).profile();
        if (p == nullptr) throw BadInput("profile: make the Bench with profile=True");
        return p->json();
    }

    // Writes the VCD and the report asked for (unless `write` is false); the Bench stays usable.
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
        bench_->serial_port(port);  // BadInput for an unknown port
        auto& s = serials_[port];
        if (!s) s = std::make_unique<PySerial>(*this, port);
        return *s;
    }

    void run_to(Picoseconds end) {
        while (bench_->now_ps() < end) {
            if (bench_->board().run_until_ps(end) == StopReason::Halted) break;
        }
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
    for (;;) {
        const std::string text = b.serial(port_).transmitted_text();
        const auto nl = text.find('\n', cursor_);
        if (nl != std::string::npos) {
            std::string line = text.substr(cursor_, nl - cursor_);
            cursor_ = nl + 1;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            return line;
        }
        if (b.now_ps() >= end) throw Timeout("serial " + (port_.empty() ? std::string("(first)") : port_) + ": no line within the timeout");
        py::gil_scoped_release release;
        bench_.run_to(std::min(end, add_ps(b.now_ps(), kPsPerMs)));
    }
}

std::string PySerial::expect(const std::string& pattern, const py::object& timeout) {
    std::regex re;
    try {
        re = std::regex(pattern);
    } catch (const std::regex_error& e) {
        throw BadInput("expect: '" + pattern + "' is not a regular expression: " + e.what());
    }
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
        if (std::regex_search(line, re)) return line;
    }
}

void PySerial::stream_gcode(const std::string& path, const std::string& family, const std::string& flow) {
    UartHostOptions o = default_host_options(bench_.bench().serial_port(port_));
    if (!family.empty()) o.family = parse_firmware_family(family, "family");
    if (!flow.empty()) o.flow = parse_flow_control(flow, "flow");
    bench_.bench().host(port_, o).load_file(path);
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
        .def("symbol", [](const Mcu& mcu, const std::string& symbol, std::size_t size) {
                 if (size != 1 && size != 2 && size != 4) throw BadInput("symbol: size 1, 2 or 4 bytes");
                 const auto bytes = mcu.read_ram(symbol, size);
                 std::uint32_t v = 0;
                 for (std::size_t i = size; i-- > 0;) v = (v << 8) | bytes[i];
                 return v;
             }, py::arg("name"), py::arg("size") = 1, "an unsigned little-endian variable of 1, 2 or 4 bytes")
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
        .def_property_readonly("readouts", [](Part& p) {
            py::dict d;
            for (const auto& r : p.readouts()) d[py::str(r.name)] = r.value();
            return d;
        })
        .def("signal", [](Part& p, const std::string& name) {
            for (std::size_t i = 0; i < p.signals().size(); ++i) {
                if (p.signals()[i].name == name) return p.signal_value(i);
            }
            for (const auto& r : p.readouts()) {
                if (r.name == name) return r.value();
            }
            std::string names;
            for (const auto& s : p.signals()) names += (names.empty() ? "" : ", ") + s.name;
            for (const auto& r : p.readouts()) names += (names.empty() ? "" : ", ") + r.name;
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
        .def(py::init<const std::string&, std::map<std::string, std::string>, std::string, std::string, bool>(),
             py::arg("board"), py::arg("firmware"), py::arg("vcd") = "", py::arg("report") = "", py::arg("profile") = false)
        .def("run_for", &PyBench::run_for)
        .def("run_until", &PyBench::run_until, py::arg("predicate"), py::arg("timeout"), py::arg("step"))
        .def("run_until_idle", &PyBench::run_until_idle, py::arg("max"), py::arg("settle"))
        .def_property_readonly("left_going", [](PyBench& b) { return b.bench().left_going(); })
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
    static py::exception<BadInput> bad_input(m, "BadInput");
    static py::exception<Timeout> timeout(m, "Timeout");
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
