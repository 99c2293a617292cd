// A rotary incremental encoder with quadrature outputs on a turning shaft
// (an Omron E6B2-C, a CUI AMT10x): port `shaft` requires `steps` (a
// step_dir_driver's steps, or a stepper motor's rotor, whose lag and lost
// steps the encoder then sees as a real one would). Pins `a` and `b` go
// through the four quadrature states per line, A leading B while the shaft
// turns forward (00 -> 10 -> 11 -> 01), push-pull or open collector.
//
// What it finds: A/B edges closer together than the MCU's decoder can take
// (`min_edge_spacing`, the time its pin-change ISR needs): counts the
// firmware misses. Edges in the same instant (a shaft that jumps several
// counts in one step) are 0 apart. One finding at the first such edge; the
// summary counts them all (a fast move makes thousands).
#pragma once

#include <cstdint>

#include "parts/Params.hpp"
#include "parts/Part.hpp"
#include "parts/ShaftMotion.hpp"

namespace avrbench {

class QuadratureEncoder final : public Part {
public:
    static const FindingKind kEdgesTooFast;  // encoder-edges-too-fast
    static std::vector<ParamSpec> param_specs();

    QuadratureEncoder(std::string name, Mcu& clock, const ParamValues& params);
    std::string_view type() const override { return "quadrature_encoder"; }
    void start() override;
    std::string summary() override;

    // Quadrature counts from the start (4 per line), signed: + forward.
    std::int64_t count() const { return count_; }
    std::uint64_t edges() const { return edges_; }

private:
    void connect_shaft(ShaftMotion& shaft);
    void follow_shaft();
    void step_count(int direction);
    void drive(std::size_t pin, bool level);

    ShaftMotion* shaft_ = nullptr;
    std::int64_t lines_per_rev_;
    std::int64_t full_steps_per_rev_;
    bool open_collector_;
    Cycle min_spacing_cycles_;
    std::size_t pin_a_, pin_b_;
    std::size_t sig_count_ = 0;
    std::int64_t start_256_ = 0;  // the shaft's position at connection, 1/256 full steps
    std::int64_t count_ = 0;
    std::uint64_t edges_ = 0;
    bool have_edge_ = false;
    Cycle last_edge_ = 0;
    Cycle closest_cycles_ = 0;
    std::uint64_t too_close_ = 0;  // edges closer than min_spacing_cycles_ to the one before
};

}  // namespace avrbench
