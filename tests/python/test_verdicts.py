"""Verdicts from Python: run_until_idle returns "idle" only when the
firmware is done, lines written by hand included, and its other answers
are the documented strings (docs/PYTHON.md)."""
import pytest

import avrbench


def test_a_line_written_before_the_firmware_boots_is_waited_for(elf):
    # grbl_stepper (firmware/boards/grbl_stepper) answers "ok" once a move is
    # made; X2000 is 2000 steps at its default 8000 steps/s: 0.25 s of
    # stepping, after a boot that takes the line only once RXEN is set.
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    bench.serial().write(b"X2000\n")
    assert bench.run_until_idle(max="5s") == "idle"
    assert bench.axis("x").steps == 2000
    assert bench.now > 2000 / 8000


def test_an_unfinished_run_says_time_limit_and_what_was_going(elf):
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    bench.serial().write(b"X2000\n")
    assert bench.run_until_idle(max="10ms") == "time-limit"
    going = bench.still_going
    assert any("'X2000'" in why and "written by hand" in why for why in going), going


def test_a_host_that_gave_up_is_host_failed(elf, tmp_path):
    # grbl_stepper never prints grbl's welcome: a grbl host waiting for it
    # gives up after its 10 s banner timeout (stimulus/UartHost.hpp).
    job = tmp_path / "job.gcode"
    job.write_text("X1\n")
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    bench.serial().stream_gcode(str(job), family="grbl")
    assert bench.run_until_idle(max="20s") == "host-failed"
