"""avrbench for Python: an unmodified AVR firmware ELF on an emulated board,
driven from pytest (docs/PYTHON.md).

    import avrbench
    with avrbench.Bench("arduino-uno-cnc-shield-v3", "grbl.elf", vcd="job.vcd") as bench:
        port = bench.serial()
        port.expect(r"^Grbl", timeout="1s")
        port.write(b"G1 X10 F600\\n")
        port.expect(r"^ok", timeout="1s")
        bench.run_until_idle(max="10s")
        assert bench.part("x").position_mm == 10.0

Time is simulated time only: durations are "250ms"-style strings or seconds,
and every wait is bounded by its timeout in simulated time. Errors are
exceptions with the command-line tool's one-line messages: BadInput (what
`avrbench` exits 2 for), Timeout (what it exits 3 for).
"""
import json as _json

from ._avrbench import BadInput, Finding, Timeout  # noqa: F401
from . import _avrbench

__all__ = ["Bench", "BadInput", "Timeout", "Finding", "Part", "Net"]


class Part:
    """A part of the board: each signal and readout it declares is an
    attribute (`part.position_mm`, `part.block_degC`, `part.steps`), its
    faults are controls."""

    def __init__(self, native):
        object.__setattr__(self, "_native", native)

    @property
    def name(self):
        return self._native.name

    @property
    def signals(self):
        """Every signal the part declares, name -> present value."""
        return self._native.signals

    @property
    def readouts(self):
        """Values the part offers that are not traced signals (an axis's steps), name -> present value."""
        return self._native.readouts

    @property
    def faults(self):
        return self._native.faults

    @property
    def fault(self):
        return self._native.fault

    def inject_fault(self, fault):
        """Applies one of `faults` now ("none" repairs)."""
        self._native.inject_fault(fault)

    def trigger(self):
        """The part's first fault other than "none" (a switch's "stuck-closed", ...)."""
        faults = [f for f in self._native.faults if f != "none"]
        if not faults:
            raise BadInput(f"part {self.name} has no fault to trigger")
        self._native.inject_fault(faults[0])

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        return self._native.signal(name)

    def __repr__(self):
        return f"<avrbench.Part {self.name} {self.signals}>"


class Net:
    """A net, label or MCU pin (`uno.PB5`) of the board."""

    def __init__(self, bench, name):
        self._bench, self.name = bench, name

    @property
    def level(self):
        return int(self._bench._native.level(self.name))

    def drive(self, level):
        """Drives it as a push-pull output of the bench would (a test probe)."""
        self._bench._native.drive(self.name, bool(level))

    def release(self):
        self._bench._native.release(self.name)


class Bench:
    """A board with its firmware. `firmware`: one ELF for the board's first
    MCU, or {mcu: elf}; MCUs not named run the board file's `firmware:`.
    `vcd` and `report` are written by close() (or leaving a `with` block);
    `profile=True` collects each MCU's timing profile."""

    def __init__(self, board, firmware=None, *, vcd=None, report=None, profile=False):
        if firmware is None:
            firmware = {}
        elif isinstance(firmware, (str, bytes)) or hasattr(firmware, "__fspath__"):
            firmware = {"": str(firmware)}
        elif not isinstance(firmware, dict):
            raise BadInput("firmware: an ELF path or a dict {mcu: elf}")
        firmware = {str(k): str(v) for k, v in firmware.items()}
        self._native = _avrbench.Bench(str(board), firmware, str(vcd or ""), str(report or ""), bool(profile))

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def close(self, write=True):
        """Writes the VCD (+ .gtkw) and the HTML report asked for (not when
        `write` is false: the pytest plugin keeps them for failing tests)."""
        self._native.close(write)

    # --- running --------------------------------------------------------
    def run_for(self, duration):
        self._native.run_for(duration)

    def run_until(self, predicate, timeout="1s", step="1ms"):
        """Runs in slices of `step` (simulated) until predicate() is true;
        Timeout when it is not within `timeout`."""
        self._native.run_until(predicate, timeout, step)

    def run_until_idle(self, max="10s", settle="50ms"):
        """Until the firmware is done: every G-code host's line and every line
        written with serial().write() answered, every accepted move made,
        every heater at its target, no step for `settle`. Returns "idle", or
        why not: "time-limit", "halted", "host-failed", "interrupted",
        "recorder-full" (`still_going` then says what was left)."""
        return self._native.run_until_idle(max, settle)

    @property
    def still_going(self):
        """What the last run_until_idle that did not end "idle" left going,
        one phrase each ("host host: line 3 'G1 X10' not answered", ...)."""
        return self._native.left_going

    def run_until_sleep(self, mcu="", timeout="1s"):
        """Until the MCU executes SLEEP; False when it did not within timeout."""
        return self._native.run_until_sleep(mcu, timeout)

    @property
    def now(self):
        """Simulated seconds since power-on."""
        return self._native.now

    # --- the board ------------------------------------------------------
    def mcu(self, name=""):
        return self._native.mcu(name)

    @property
    def mcus(self):
        return self._native.mcus

    def part(self, name):
        return Part(self._native.part(name))

    axis = part
    thermal = part

    @property
    def parts(self):
        return self._native.parts

    def net(self, name):
        return Net(self, name)

    pin = net

    def serial(self, port=""):
        return self._native.serial(port)

    @property
    def findings(self):
        return self._native.findings

    # --- what was recorded ----------------------------------------------
    def timeline(self, signal):
        """(cycles, values) of one recorded signal ("uno.PB5", "x.position_mm")
        as numpy arrays."""
        return self._native.timeline(signal)

    def timeline_text(self):
        """The timeline in the golden-timeline format (docs/SCENARIOS.md)."""
        return self._native.timeline_text()

    def profile(self, mcu=""):
        """The MCU's timing profile as `run --profile` writes it (a dict)."""
        return _json.loads(self._native.profile_json(mcu))
