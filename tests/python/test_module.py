"""The avrbench Python module on real firmware in real simavr. Expected
values from the firmware's sources and binutils, the CLI's own output for
"the same message", and the scenario run for "the same timeline"."""
import random
import re
import shutil
import subprocess
import threading
import time

import numpy as np
import pytest

import avrbench


def nm(elf_path, name):
    for line in subprocess.run(["avr-nm", elf_path], capture_output=True, text=True, check=True).stdout.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] == name:
            return int(parts[0], 16)
    raise AssertionError(name)


def test_a_blink_toggles_every_16000_cycles(elf):
    # firmware/blink_timer1: (OCR1A + 1) * N = 250 * 64 = 16000 cycles per toggle.
    bench = avrbench.Bench("arduino-uno", elf("blink_timer1"))
    bench.run_for("20ms")
    cycles, levels = bench.timeline("uno.PB5")
    assert cycles.dtype == np.uint64
    assert set(np.diff(cycles[1:]).tolist()) == {16000}
    # The initial level, then toggles one period (16000) plus the start-up
    # after power-on: 19 fit in 20 ms (320 000 cycles) when the start-up is
    # longer than one cycle, as avr-libc's crt0 alone is.
    assert len(cycles) == 1 + 19
    assert 16000 < cycles[1] < 17000
    assert bench.now == pytest.approx(0.02, abs=1e-6)
    assert bench.net("uno.PB5").level == int(levels[-1])


def test_variables_by_symbol_and_a_run_until(elf):
    # firmware/gdb_target: tick() adds 3 to ticks once per pass of main's loop.
    bench = avrbench.Bench("arduino-uno", elf("gdb_target"))
    mcu = bench.mcu("uno")
    bench.run_until(lambda: mcu.symbol("ticks", size=2) >= 30, timeout="10ms", step="10us")
    assert mcu.symbol("ticks", size=2) % 3 == 0
    mcu.write("ticks", (1000).to_bytes(2, "little"))
    assert mcu.read("ticks", 2) == (1000).to_bytes(2, "little")
    bench.run_for("20us")  # a pass is ~15 instructions: several more ticks
    assert mcu.symbol("ticks", size=2) > 1000 and (mcu.symbol("ticks", size=2) - 1000) % 3 == 0
    assert mcu.cycle > 0 and mcu.frequency_hz == 16000000


def test_findings_are_objects_with_pc_symbol_and_cycle(elf):
    target = elf("crash_bad_opcode")
    bench = avrbench.Bench("arduino-uno", target)
    bench.run_for("10ms")
    assert len(bench.findings) == 1
    f = bench.findings[0]
    assert f.kind == "invalid-opcode" and f.severity == "error"
    assert f.pc == nm(target, "bad_opcode_here")
    assert f.symbol == "bad_opcode_here"
    assert "invalid-opcode" in str(f) and f.source == "uno"


def test_a_part_shows_every_signal_it_declares(elf):
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    x = bench.part("x")
    assert x.position_mm == pytest.approx(100.0)  # the board file's start_position
    assert "position_mm" in x.signals
    with pytest.raises(avrbench.BadInput, match="has no signal 'speed'"):
        x.speed
    assert "x_limit" in bench.parts


def test_driving_a_pin_reaches_the_firmware(elf):
    # grbl_stepper: a limit input (PB1, to ground) going low runs the pin
    # change vector, which sets `alarm`; a move is then refused with error:9.
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    bench.serial().expect(r"^avrbench grbl_stepper", timeout="100ms")
    assert bench.net("uno.PB1").level == 1  # internal pull-up
    bench.net("uno.PB1").drive(0)
    bench.run_for("1ms")
    assert bench.mcu().symbol("alarm") == 1
    bench.serial().write(b"X10\n")
    assert bench.serial().read_line(timeout="50ms") == "error:9"
    bench.net("uno.PB1").release()
    bench.run_for("1ms")
    assert bench.net("uno.PB1").level == 1


def test_triggering_a_limit_switch_alarms_the_firmware(elf):
    # The switch's first fault is stuck_closed (bench/parts/LimitSwitch.hpp):
    # its input PB1 goes to ground and grbl_stepper's pin change vector sets `alarm`.
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    bench.serial().expect(r"^avrbench grbl_stepper", timeout="100ms")
    x_limit = bench.part("x_limit")
    assert x_limit.faults == ["stuck_closed", "stuck_open"]
    x_limit.trigger()
    bench.run_for("1ms")
    assert x_limit.fault == "stuck_closed" and x_limit.closed == 1
    assert bench.mcu().symbol("alarm") == 1


def test_a_gcode_file_streams_through_the_boards_host(elf, tmp_path):
    # grbl_stepper answers "ok" per line (not grbl's banner): family generic.
    # 100 and 200 steps at 250 steps/mm from 100 mm: 100.4 and 100.8 mm.
    job = tmp_path / "job.gcode"
    job.write_text("X100\nY200\n")
    bench = avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper"))
    bench.serial().stream_gcode(str(job), family="generic")
    assert bench.run_until_idle(max="5s") == "idle"
    assert bench.part("x").position_mm == pytest.approx(100.4)
    assert bench.part("y").position_mm == pytest.approx(100.8)
    # Readouts beside the signals: the STEP pulses each driver took.
    assert bench.axis("x").steps == 100 and bench.axis("y").steps == 200
    assert bench.axis("x").readouts == {"steps": 100.0, "position_steps": bench.axis("x").position_steps}
    with pytest.raises(avrbench.BadInput):
        avrbench.Bench("arduino-uno-cnc-shield-v3", elf("grbl_stepper")).serial().stream_gcode(str(job), family="nope")


def test_a_bad_board_path_raises_bad_input_with_the_cli_message(elf, cli):
    r = subprocess.run([cli, "run", "--board", "/nonexistent/board.yaml", elf("blink_timer1")], capture_output=True,
                       text=True)
    assert r.returncode == 2
    cli_message = r.stderr.strip().removeprefix("avrbench: error: ")
    with pytest.raises(avrbench.BadInput) as raised:
        avrbench.Bench("/nonexistent/board.yaml", elf("blink_timer1"))
    assert str(raised.value) == cli_message


def test_a_wait_that_never_ends_is_a_timeout_in_simulated_time(elf):
    bench = avrbench.Bench("arduino-uno", elf("blink_timer1"))
    with pytest.raises(avrbench.Timeout):
        bench.serial().read_line(timeout="5ms")  # blink_timer1 never transmits
    assert bench.now == pytest.approx(0.005, abs=1e-4)
    with pytest.raises(avrbench.Timeout):
        bench.run_until(lambda: False, timeout="2ms")


def test_the_same_scenario_gives_the_same_timeline_byte_for_byte(elf, cli, root, tmp_path):
    """tests/scenarios/blink_timer1.yaml (20 ms on arduino-uno) through
    `avrbench golden update` and through Python: identical timelines."""
    scenario = (root / "tests" / "scenarios" / "blink_timer1.yaml").read_text()
    scenario = scenario.replace("../../bench/boards/arduino-uno.yaml", str(root / "bench" / "boards" / "arduino-uno.yaml"))
    scenario = scenario.replace("../../golden/blink_timer1.timeline", "blink.timeline")
    (tmp_path / "blink.yaml").write_text(scenario)
    r = subprocess.run([cli, "golden", "update", str(tmp_path / "blink.yaml"), "--firmware-dir",
                        str(elf("x")).rsplit("/", 1)[0]], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    from_check = (tmp_path / "blink.timeline").read_text()
    bench = avrbench.Bench("arduino-uno", elf("blink_timer1"))
    bench.run_for("20ms")
    from_python = bench.timeline_text()
    # The header lists the scenario's input files (Python has none); from "end" on, the timeline.
    body = lambda text: text[text.index("\nend "):]
    assert body(from_python) == body(from_check)


def test_vcd_and_report_are_written_on_close(elf, tmp_path):
    with avrbench.Bench("arduino-uno", elf("blink_timer1"), vcd=tmp_path / "b.vcd", report=tmp_path / "b.html") as bench:
        bench.run_for("5ms")
    vcd = (tmp_path / "b.vcd").read_text()
    assert "$enddefinitions" in vcd and (tmp_path / "b.gtkw").exists()
    assert (tmp_path / "b.html").read_text().startswith("<!DOCTYPE html>")
    # sigrok-cli (ci/setup installs it) reads it: absent, the test fails rather than skip the check.
    assert shutil.which("sigrok-cli"), "sigrok-cli is not installed (bash ci/setup)"
    r = subprocess.run(["sigrok-cli", "-I", "vcd", "-i", str(tmp_path / "b.vcd"), "--show"], capture_output=True)
    assert r.returncode == 0


def test_the_timing_profile(elf):
    # blink_timer1's compare-match ISR is 28 cycles (tests/scenarios/blink_timer1_timing.yaml, hand-counted).
    bench = avrbench.Bench("arduino-uno", elf("blink_timer1"), profile=True)
    bench.run_for("10ms")
    profile = bench.profile("uno")
    assert profile["mcu"] == "uno"
    isr = next(v for v in profile["vectors"] if v["runs"] >= 9)  # 9 or 10 compare matches in 10 ms
    assert isr["inclusive_cycles"]["max"] == 28


def test_the_gil_is_released_while_the_simulation_runs(elf):
    """While one thread is inside run_for, another thread's Python code runs
    and sees the simulated time advance: with the GIL held it could only
    look between runs, when `now` is a whole number of the 200 ms runs.
    Counted as distinct times seen that are not, until there are more than
    10 - however fast or slow the machine is (bounded by a wall-clock guard,
    not by a duration the run must outlast)."""
    bench = avrbench.Bench("arduino-uno", elf("busy_poll"))
    done = threading.Event()
    seen_during_runs = set()

    def run():
        while not done.is_set():
            bench.run_for("200ms")

    worker = threading.Thread(target=run)
    worker.start()
    deadline = time.monotonic() + 120  # a guard against a hang, not a budget
    while len(seen_during_runs) <= 10 and time.monotonic() < deadline:
        now = bench.now  # reads a property: needs the GIL
        if abs(now / 0.2 - round(now / 0.2)) > 1e-6:  # inside a run, not at its start or end
            seen_during_runs.add(now)
    done.set()
    worker.join()
    assert len(seen_during_runs) > 10


def test_bad_arguments_raise_exceptions_and_never_crash(elf):
    """A little fuzzing of the binding's argument parsing: seeded random
    values of the wrong kinds; only avrbench's and Python's own argument
    exceptions may come out."""
    rng = random.Random(39)
    junk = [None, -1, 0, 1e300, float("nan"), "", "x", "-5ms", "1e9s", "250zz", "uno.PB99", b"\xff", [], {}, {"": 3},
            "../../etc/passwd", "a" * 5000]
    bench = avrbench.Bench("arduino-uno", elf("blink_timer1"))
    calls = [
        lambda a: avrbench.Bench(a, elf("blink_timer1")),
        lambda a: avrbench.Bench("arduino-uno", a),
        lambda a: bench.run_for(a),
        lambda a: bench.run_until(lambda: True, timeout=a),
        lambda a: bench.mcu(a),
        lambda a: bench.mcu("uno").read(a, 2),
        lambda a: bench.mcu("uno").symbol("ticks", size=a),
        lambda a: bench.part(a),
        lambda a: bench.net(a).level,
        lambda a: bench.net(a).drive(1),
        lambda a: bench.serial(a),
        lambda a: bench.serial().expect(a, timeout="1ms"),
        lambda a: bench.timeline(a),
        lambda a: bench.profile(a),
    ]
    for _ in range(300):
        try:
            rng.choice(calls)(rng.choice(junk))
        except (avrbench.BadInput, avrbench.Timeout, TypeError, ValueError, OverflowError):
            pass
    bench.run_for("1ms")  # still works


def test_a_deprecated_serial_section_is_a_deprecation_warning(elf, tmp_path):
    # docs/BOARDS.md: the old `serial:` section still loads, as a serial_host
    # on the USART's pins, and says it is deprecated - in Python, a warning
    # the caller's filters can turn into an error.
    board = tmp_path / "old-serial-python.yaml"
    board.write_text("mcus:\n  uno: {type: atmega328p, clock: 16MHz}\n"
                     "serial:\n  host: {mcu: uno, usart: 0}\n")
    with pytest.warns(DeprecationWarning, match=r"old-serial-python.yaml:4: 'serial:' is deprecated"):
        bench = avrbench.Bench(str(board), elf("uart_echo"))
    bench.run_for("5ms")
    assert bench.serial("host").received.startswith("avrbench uart_echo")


def test_an_lcd_shows_its_text_and_lines(elf):
    # firmware/boards/lcd_hello on the Einsy RAMBo's 20x4 HD44780: line 1
    # "Hello, Einsy", line 4 "Temp 215" with the ROM's degree sign (0xDF).
    bench = avrbench.Bench("einsy-rambo", elf("lcd_hello"))
    bench.run_for("100ms")
    lcd = bench.part("lcd")
    assert lcd.lines == ["Hello, Einsy".ljust(20), " " * 20, " " * 20, "Temp 215\u00b0C".ljust(20)]
    assert lcd.text == "\n".join(lcd.lines)
    assert lcd.writes > 0


def test_a_knob_is_turned_and_pressed_from_python(elf):
    # firmware/boards/knob_menu counts detents (4 transitions each) and clicks.
    bench = avrbench.Bench("einsy-rambo", elf("knob_menu"))
    bench.run_for("100ms")
    knob = bench.part("knob")
    assert set(knob.actions) == {"press", "release", "turn"}
    knob.turn(2)            # 8 transitions, 25 ms apart at 10 detents/s
    bench.run_for("300ms")
    knob.press()
    bench.run_for("50ms")
    knob.release()
    bench.run_for("50ms")
    mcu = bench.mcu()
    assert mcu.symbol("detents", size=2) == 2
    assert mcu.symbol("clicks", size=2) == 1
    assert bench.part("lcd").lines[0].rstrip() == "Item 2"


def test_symbols_take_their_size_from_the_elf_and_a_sign_when_asked(elf):
    # knob_menu: `int16_t detents`, `uint16_t clicks` (2 bytes each in the
    # symbol table, avr-nm -S).
    bench = avrbench.Bench("einsy-rambo", elf("knob_menu"))
    bench.run_for("100ms")
    bench.part("knob").turn(-2)
    bench.run_for("300ms")
    mcu = bench.mcu()
    assert mcu.symbol("detents", signed=True) == -2
    assert mcu.symbol("detents") == 0x10000 - 2        # the same two bytes, unsigned
    with pytest.raises(avrbench.BadInput, match="is 2 bytes in the ELF; size=4 would read past it"):
        mcu.symbol("clicks", size=4)
