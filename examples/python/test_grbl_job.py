"""A grbl-style job tested as a firmware team would: grbl_stepper on an UNO
with a CNC shield (bench/boards/arduino-uno-cnc-shield-v3.yaml).

Expected values from the firmware's documentation (firmware/boards/
grbl_stepper/main.c: its banner, one "ok" per command, "error:3" for a
setting it does not have, "?" answers <X,Y,Z> in steps,
2000 cycles per step at the default rates) and the board file (250 steps/mm,
every axis starting at 100 mm)."""
import numpy as np
import pytest

import avrbench

BOARD = "arduino-uno-cnc-shield-v3"


@pytest.fixture
def grbl(firmware):
    with avrbench.Bench(BOARD, firmware("grbl_stepper")) as bench:
        bench.serial().expect(r"^avrbench grbl_stepper", timeout="100ms")  # its banner
        yield bench


def test_a_move_ends_where_the_command_says(grbl):
    port = grbl.serial()
    port.write(b"X1600 Y800\n")
    port.expect(r"^ok$", timeout="2s")  # answered when the move is done
    grbl.run_for("20ms")
    port.write(b"?\n")
    assert port.expect(r"^<", timeout="100ms") == "<1600,800,0>"
    # 1600 steps / 250 steps/mm = 6.4 mm from 100 mm; 800 steps = 3.2 mm.
    assert grbl.part("x").position_mm == pytest.approx(106.4)
    assert grbl.part("y").position_mm == pytest.approx(103.2)
    assert grbl.findings == []


def test_steps_come_at_the_default_rate(grbl):
    grbl.serial().write(b"X400\n")
    grbl.serial().expect(r"^ok$", timeout="1s")
    cycles, levels = grbl.timeline("uno.PD2")  # X STEP
    rises = cycles[levels == 1]
    assert len(rises) == 400
    # 6000 mm/min at 80 steps/mm = 8000 steps/s: 16 MHz / 8000 = 2000 cycles.
    assert np.median(np.diff(rises)) == 2000


def test_an_unknown_setting_is_refused(grbl):
    port = grbl.serial()
    port.write(b"$999=1\n")  # no setting 999: "error:3", as grbl's bad-setting error
    assert port.read_line(timeout="100ms") == "error:3"
