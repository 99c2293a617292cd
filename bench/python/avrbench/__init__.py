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

from ._avrbench import BadInput, Error, Finding, Timeout  # noqa: F401
from . import _avrbench

__all__ = ["Bench", "Error", "BadInput", "Timeout", "Finding", "Part", "Net", "Mcu", "Serial"]


def _check_open(bench):
    if bench._native.closed:
        raise BadInput("this Bench is closed (close() or the end of its `with` block); make a new one")


class _OfBench:
    """A view of one piece of a Bench, refusing every use once the Bench is
    closed (avrbench.BadInput), as the Bench itself does."""

    def __init__(self, bench, native):
        object.__setattr__(self, "_bench", bench)
        object.__setattr__(self, "_native", native)

    def __getattr__(self, name):
        if name.startswith("_"):
            raise AttributeError(name)
        _check_open(self._bench)
        return getattr(self._native, name)


class Mcu(_OfBench):
    """An MCU of the board: `.cycle`, `.seconds`, `.pc` (byte address),
    `.sp`, `.sleeping`, `.halted`, `.frequency_hz`, `.name`, `.type`;
    `.symbol(name)` a variable's value, `.read(symbol, size)` its bytes,
    `.write(symbol, data)`."""

    def __repr__(self):
        return f"<avrbench.Mcu {self._native.name}>"


class Serial(_OfBench):
    """A serial port of the board, as a host program sees it.

    write(data)           bytes to the firmware; each line in them is one the
                          firmware must answer before run_until_idle is done
    read_line(timeout)    the firmware's next line (without its line end);
                          avrbench.Timeout when none comes within `timeout`
    expect(pattern, timeout)  the next line matching the regular expression
                          (RE2: linear time, no backreferences or lookaround)
    stream_gcode(path, family="", flow="")  the board's G-code host sends
                          the file with the port's protocol (family, flow:
                          overrides, as `run --family/--flow`); a grbl family
                          waits up to 10 s for grbl's welcome first
    received              everything the firmware sent, as text
    """

    def __repr__(self):
        return "<avrbench.Serial>"


class Part:
    """A part of the board: each signal and readout it declares is an
    attribute (`part.position_mm`, `part.block_degC`, `part.steps`), its
    faults are controls."""

    def __init__(self, native, bench=None):
        object.__setattr__(self, "_native", native)
        object.__setattr__(self, "_bench", bench)

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

    @property
    def actions(self):
        """What can be done to the part (a knob's "press", "release", "turn"), each a method."""
        return self._native.actions

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
        if self._bench is not None:
            _check_open(self._bench)
        if name in self._native.actions:
            # An action (a knob's press(), release(), turn(3)): done now, in simulated time.
            def action(*arguments):
                if self._bench is not None:
                    _check_open(self._bench)
                self._native.act(name, [float(a) for a in arguments])
            return action
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
    `profile=True` collects each MCU's timing profile. `max_events`: the
    most events the run may record (default 5*10^7, about 1.2 GB); a run
    past it raises avrbench.BadInput, as the CLI exits 2."""

    def __init__(self, board, firmware=None, *, vcd=None, report=None, profile=False, max_events=0):
        if firmware is None:
            firmware = {}
        elif isinstance(firmware, (str, bytes)) or hasattr(firmware, "__fspath__"):
            firmware = {"": str(firmware)}
        elif not isinstance(firmware, dict):
            raise BadInput("firmware: an ELF path or a dict {mcu: elf}")
        firmware = {str(k): str(v) for k, v in firmware.items()}
        if not isinstance(max_events, int) or max_events < 0:
            raise BadInput("max_events: a count of events, 0 for the default")
        self._native = _avrbench.Bench(str(board), firmware, str(vcd or ""), str(report or ""), bool(profile), max_events)

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
        """The MCU `name` (the board's first by default): an avrbench.Mcu."""
        return Mcu(self, self._native.mcu(name))

    @property
    def mcus(self):
        return self._native.mcus

    def part(self, name):
        return Part(self._native.part(name), self)

    axis = part
    thermal = part

    @property
    def parts(self):
        return self._native.parts

    def net(self, name):
        return Net(self, name)

    pin = net

    def serial(self, port=""):
        """Serial port `port` of the board (its first by default): an
        avrbench.Serial (help(avrbench.Serial) lists what it does)."""
        return Serial(self, self._native.serial(port))

    @property
    def findings(self):
        return self._native.findings

    # --- what was recorded ----------------------------------------------
    def timeline(self, signal):
        """(cycles, values) of one recorded signal as numpy arrays: a net's or
        label's name ("x_step", "led") or "scope.name" ("uno.PB5",
        "x.position_mm", "nets.x_step"); `timeline_signals` lists them."""
        return self._native.timeline(signal)

    @property
    def timeline_signals(self):
        """Every name timeline() takes ("scope.name"), aliases included."""
        return self._native.timeline_signals

    def timeline_text(self):
        """The timeline in the golden-timeline format (docs/SCENARIOS.md)."""
        return self._native.timeline_text()

    def profile(self, mcu=""):
        """The MCU's timing profile as `run --profile` writes it (a dict)."""
        return _json.loads(self._native.profile_json(mcu))
