"""A hot end held by PID (firmware/thermal/pid_heater: Marlin 1.1's PID
defaults, target 200 degC) on a RAMPS 1.4 (bench/boards/ramps-1.4.yaml:
the hot end's thermal plant on D10 and T0), tested as a firmware team would.

Expected values: the target from the firmware's source (TARGET_C = 200);
the firmware's own reading (temp_x10, 0.1 degC) against the plant's sensor
temperature within 2 degC: the EPCOS 100k table's steps near 200 degC are
about 1 degC per ADC count (docs/THERMAL.md)."""
import pytest

import avrbench


@pytest.mark.parametrize("seconds", [120])
def test_the_hot_end_reaches_its_target_and_stays_there(firmware, seconds):
    with avrbench.Bench("ramps-1.4", firmware("thermal_pid")) as bench:
        hotend = bench.part("hotend")
        bench.run_until(lambda: hotend.block_degC >= 195, timeout=f"{seconds}s", step="100ms")
        peak = hotend.block_degC
        for _ in range(100):  # 10 s more, watching the overshoot
            bench.run_for("100ms")
            peak = max(peak, hotend.block_degC)
        assert hotend.block_degC == pytest.approx(200, abs=3)
        assert peak < 215
        reading = bench.mcu("mega").symbol("temp_x10", size=2) / 10
        assert reading == pytest.approx(hotend.sensor_degC, abs=2)
        assert bench.findings == []
