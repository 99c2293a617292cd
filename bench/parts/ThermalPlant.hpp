// The thermal plant of a hot end or a heated bed: a lumped network
// (ThermalNetwork) of
//   block    the heated mass (hot end heater block; the bed's heater plate),
//            losing heat to ambient through a conductance that the
//            part-cooling fan raises (Marlin's MPC model: g = g0 + s·(g255 − g0))
//            and the filament feed adds to (feed rate × heat capacity per mm);
//   surface  optional second mass joined to the block (the bed's glass),
//            losing heat to ambient on its own;
//   sensor   the thermistor bead: a massless follower of the block with its
//            own time constant (Marlin MPC's "sensor responsiveness" = 1/τ),
//            or the block itself when the time constant is 0.
// Heaters, fans and thermistors are separate parts that refer to the plant by
// name. The state advances lazily and exactly (no time step) whenever an input
// changes or somebody reads a temperature, at the plant clock's cycle.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ShaftMotion.hpp"
#include "parts/ThermalBody.hpp"
#include "parts/ThermalNetwork.hpp"

namespace avrbench {

class ThermalPlant final : public Part, public ThermalBody {
public:
    // What this part finds (`avrbench findings` lists every kind).
    static const FindingKind kOverheat;  // overheat
    static const FindingKind kHeatingUnmonitored;  // heating-unmonitored
    static const FindingKind kReadyWhileCold;      // ready-while-cold
    static std::vector<ParamSpec> param_specs();
    static const std::map<std::string, std::map<std::string, std::string>>& presets();

    // Port `body` provides the plant to heaters, thermistors and fans; port
    // `filament` (optional) requires the extruder's step_dir_driver `steps`,
    // whose steps feed cold filament.
    ThermalPlant(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "thermal_plant"; }
    void start() override;
    std::string summary() override;
    // Heat put in since the mark (a heater on now or switched on since): it
    // may go on to overheat the plant.
    void mark_pace() override;
    bool may_find_more_at_pace(double seconds) override;

    // Temperatures now (advances the model to the clock's current cycle).
    double block_degC();
    double sensor_degC() override;
    double surface_degC();  // the block's if there is no surface node
    double ambient_degC() const { return network_.ambient(); }
    void set_ambient_degC(double degC);

    // Inputs. Each advances the model to now with the old value first.
    // A heat source is one heater's contribution to one node ("block" or "surface").
    // A heater of at most `max_power_W` on "block" or "surface"; BadInput if
    // the pair would heat that node faster than kMaxHeatingRate_K_per_s.
    int add_heat_source(const std::string& node, double max_power_W) override;
    static constexpr double kMaxHeatingRate_K_per_s = 1000;
    void set_heat_source_power(int source, double watts) override;
    void set_fan_speed(double fraction) override;  // 0..1 of full speed
    void set_filament_feed_mm_per_s(double rate); // filament entering the melt zone
    // Sensor detached: it follows ambient instead of the block (a thermistor
    // fallen out of its bore).
    void set_sensor_detached(bool detached) override;
    void attach_sensor() override { ++sensors_; }
    void sensor_read(Cycle cycle) override;

    double fan_speed() const override { return fan_speed_; }
    double filament_feed_mm_per_s() const { return feed_mm_per_s_; }
    double heater_power_W() const;
    bool sensor_detached() const { return detached_; }

    // Energy since start (or reset_energy()), J: heater input, stored in the
    // masses, lost to ambient (convection, fan, filament).
    double energy_in_J();
    double energy_stored_J();
    double energy_lost_J();
    void reset_energy();

    // The network, for checks (advance() first to bring it to now).
    void advance();
    const ThermalNetwork& network() const { return network_; }
    int block_node() const { return block_; }
    int surface_node() const { return surface_; }
    int sensor_node() const { return sensor_; }
    double max_degC() const { return max_degC_; }

private:
    void connect_filament(ShaftMotion& feed);
    void apply_conductance();
    void on_sample(Cycle scheduled);

    ThermalNetwork network_;
    int block_ = -1, surface_ = -1, sensor_ = -1;
    double g_ambient_, g_ambient_fan_, filament_J_per_K_mm_;
    double max_degC_;
    bool diverged_ = false;  // a temperature stopped being a finite number (reported once)
    double fan_speed_ = 0, feed_mm_per_s_ = 0;
    bool detached_ = false;
    bool heated_ = false;       // a heat source was ever turned on
    Cycle last_heat_cycle_ = 0;  // the last time one was
    Cycle pace_cycle_ = 0;       // mark_pace()
    bool overheated_ = false;
    // heating-unmonitored: thermistors on the body, the last one read, and
    // whether a heater was on since the last sample.
    int sensors_ = 0;
    Cycle last_sensor_read_ = 0;
    Cycle unmonitored_cycles_ = 0;
    bool heated_since_sample_ = false;
    bool unmonitored_reported_ = false;
    void check_monitoring(Cycle now);
    // ready-while-cold: the firmware's "at temperature" line on pin `ready`.
    std::size_t ready_pin_ = 0;
    double ready_min_degC_ = 0;
    bool ready_reported_ = false;
    void check_ready();
    void on_input(std::size_t pin, bool level) override;
    std::vector<std::pair<int, double>> sources_;  // node, watts
    Cycle last_cycle_ = 0;
    Cycle sample_cycles_;

    ShaftMotion* filament_driver_ = nullptr;
    double filament_steps_per_mm_;
    std::int64_t feed_256_ = 0;  // driver steps in 1/256 full steps since the last sample
    double filament_position_mm_ = 0, filament_high_water_mm_ = 0;
    std::size_t sig_block_, sig_sensor_, sig_surface_ = 0, sig_fan_;
};

}  // namespace avrbench
