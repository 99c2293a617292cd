#include "trace/ReportOfRun.hpp"

#include <cstdio>

#include "mcu/Mcu.hpp"
#include "mcu/TimingProfile.hpp"
#include "parts/Part.hpp"

namespace avrbench {

namespace {

// The MCUs, the board, the simulated time and each MCU's I2C traffic.
void report_facts(const RunView& run, RunReport& r) {
    for (Mcu* m : run.mcus()) {
        r.facts.push_back("MCU " + m->name() + ": " + m->mcu_type() + " at " +
                          std::to_string(m->frequency_hz() / 1000000.0).substr(0, 5) + " MHz, firmware " +
                          m->elf().path());
    }
    r.facts.push_back("board: " + run.board_path());
    char buf[64];
    std::snprintf(buf, sizeof buf, "simulated: %.6f s", run.now_seconds());
    r.facts.push_back(buf);
    // The I2C traffic each MCU's TWI took part in (its `twi` byte signal).
    for (Mcu* m : run.mcus()) {
        const long twi = run.timeline().find(m->name(), "twi");
        if (twi < 0) continue;
        std::size_t bytes = 0;
        Cycle first_cycle = 0;
        for (const TimelineEvent& e : run.timeline().events()) {
            if (e.signal != static_cast<SignalId>(twi)) continue;
            if (bytes++ == 0) first_cycle = e.cycle;
        }
        if (bytes == 0) continue;
        char text[160];
        std::snprintf(text, sizeof text, "%zu bytes (addresses and data), the first at %.6f s", bytes,
                      static_cast<double>(first_cycle) / m->frequency_hz());
        r.facts.push_back("I2C " + m->name() + ".twi: " + text);
    }
}

void report_plots(const RunView& run, RunReport& r) {
    // The report's plots come from what the parts' signals declare they are
    // (PartSignalInfo::role), not from part types.
    struct Declared {
        Part* part;
        const PartSignalInfo* info;
        SignalId id;
        std::size_t index;
    };
    std::vector<Declared> declared;
    for (Part* p : run.parts()) {
        for (std::size_t i = 0; i < p->signals().size(); ++i) {
            const PartSignalInfo& info = p->signals()[i];
            if (info.role.empty()) continue;
            const long id = run.timeline().find(p->name(), info.name);
            if (id >= 0) declared.push_back({p, &info, static_cast<SignalId>(id), i});
        }
    }
    std::vector<Part*> plants;  // parts with a temperature, in board order
    for (const Declared& d : declared) {
        if (d.info->role == "position") {
            // A position that never changed has nothing to plot.
            if (d.part->signal_changes(d.index) > 0) r.axes.push_back({d.part->name(), d.id, d.info->unit == "deg"});
        } else if (d.info->role == "temperature") {
            plants.push_back(d.part);
        } else if (d.info->role == "servo-angle") {
            r.servos.push_back({d.part->name(), d.id});
        }
    }
    // Temperature targets from the G-code the hosts sent.
    auto targets = run.temperature_targets(plants);
    for (Part* plant : plants) {
        TemperatureSeries series;
        series.name = plant->name();
        for (const Declared& d : declared) {
            if (d.part == plant && d.info->role == "temperature") series.temperature_degC = d.id;
            if (d.part == plant && d.info->role == "sensor-temperature") series.sensor_degC = d.id;
            if (d.info->concerns != plant->name()) continue;
            if (d.info->role == "heater-on") series.heater_on = d.id;
            if (d.info->role == "heater-duty") series.duty = d.id;
        }
        series.target_steps = targets[plant];
        r.temperatures.push_back(series);
    }
}

void report_faults(const RunView& run, RunReport& r) {
    for (Part* p : run.parts()) {
        for (const auto& f : p->fault_history()) {
            r.faults.push_back({static_cast<double>(f.cycle) / p->clock().frequency_hz(), f.cycle,
                                p->name() + ": " + (f.fault == "none" ? std::string("repaired") : f.fault)});
        }
    }
}

// The profiled MCUs' timing (mcu/TimingProfile.hpp).
void report_timing(const RunView& run, RunReport& r) {
    for (Mcu* m : run.mcus()) {
        const TimingProfiler* p = m->profile();
        if (p == nullptr) continue;
        TimingTable t;
        t.mcu = m->name();
        t.facts = p->summary_lines();
        for (const auto& [vector, v] : p->vectors()) {
            auto stats = [](const CycleStats& s) { return std::array<Cycle, 4>{s.min(), s.median(), s.p99(), s.max()}; };
            t.rows.push_back({vector, v.runs, v.max_depth, stats(v.inclusive_cycles), stats(v.exclusive_cycles),
                              stats(v.latency_cycles)});
        }
        // The per-vector lines are the table; the facts are the rest.
        t.facts.resize(t.facts.size() - std::min(t.facts.size(), p->vectors().size()));
        r.timing.push_back(std::move(t));
    }
}

}  // namespace

RunReport make_run_report(const RunView& run, const std::string& title) {
    RunReport r;
    r.title = title;
    r.timeline = &run.timeline();
    report_facts(run, r);
    Mcu& first = *run.mcus().front();
    r.end_cycle = first.cycle();
    r.end_clock_hz = first.frequency_hz();
    report_plots(run, r);
    report_faults(run, r);
    r.transcript = run.transcript();
    report_timing(run, r);
    r.findings = run.findings();
    for (Part* p : run.parts()) {
        auto screens = p->text_screens();
        if (screens.empty()) continue;
        DisplayScreens d{p->name(), p->clock().frequency_hz(), {}};
        for (auto& s : screens) d.screens.emplace_back(s.cycle, std::move(s.lines));
        r.displays.push_back(std::move(d));
    }
    return r;
}

std::vector<bool> report_signal_mask(const RunView& run) {
    std::vector<bool> keep(run.timeline().signals().size(), false);
    const auto mark = [&keep](long id) {
        if (id >= 0 && static_cast<std::size_t>(id) < keep.size()) keep[static_cast<std::size_t>(id)] = true;
    };
    for (Part* p : run.parts()) {
        for (const PartSignalInfo& info : p->signals()) {
            if (!info.role.empty()) mark(run.timeline().find(p->name(), info.name));
        }
    }
    for (Mcu* m : run.mcus()) mark(run.timeline().find(m->name(), "twi"));
    return keep;
}

}  // namespace avrbench
