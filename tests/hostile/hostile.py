#!/usr/bin/python3
"""Hostile inputs against the avrbench CLI (issue 32's audit, kept as a test).

Generates inputs of every class the audit found wanting - YAML alias cycles
and expansion bombs, YAML of the wrong shape, FIFOs, devices, folders and
sparse giants where a file belongs, outputs that name each other or an input,
names with newlines and escape sequences, malformed golden lines and repeat
bombs, malformed .mmcu sections, boards of hundreds of MCUs - runs the CLI on
each (the sanitized build in ci/sanitize) and checks:

  * bad input: exit 2 and exactly one line on stderr, "avrbench: error: ..."
    (or "usage error"), nothing printed that drives the terminal;
  * a legal input: the documented exit code;
  * always: no sanitizer report, at most 5 s of CPU time and 200 MB of
    memory (peak RSS), and no input or unrelated file modified.

Deterministic: the cases are generated the same way every time; --sample N
--seed S runs a seeded sample of them. Usage:

  hostile.py --cli build/avrbench --firmware-dir build/firmware --source . --work DIR [--sample N] [--seed S] [--jobs J] [--list]
"""
import argparse
import concurrent.futures
import hashlib
import os
import random
import resource
import shutil
import signal
import struct
import subprocess
import sys
import time

CPU_LIMIT_S = 5.0
RSS_LIMIT_KB = 200 * 1024
WALL_GUARD_S = 120.0  # a guard against a hang only; CPU time is the measure


class Case:
    def __init__(self, name, args, expect=2, files=None, fifos=(), sparse=None, dirs=(), check_files=(), cwd=None,
                 setup=None, says="", python=None, stdout_has=""):
        self.name = name
        self.python = python        # a script run by /usr/bin/python3 -c instead of the CLI (the module, GDB and
                                    # signal drivers); it exits 0 when the bench behaved as documented
        self.stdout_has = stdout_has  # a fragment stdout must hold
        self.says = says            # a fragment the error line must hold (so a case fails for the right reason)
        self.args = args            # argv after the CLI, with {w} for the case's folder
        self.expect = expect        # exit code (2: bad input, one line on stderr)
        self.files = files or {}    # relative path -> bytes or str
        self.fifos = fifos          # relative paths made FIFOs
        self.sparse = sparse or {}  # relative path -> (prefix bytes, size)
        self.dirs = dirs
        self.check_files = check_files  # relative paths that must be left unchanged (added to inputs)
        self.cwd = cwd              # relative folder to run in ("" = the case folder)
        self.setup = setup          # callable(folder) for anything else


# --- building blocks --------------------------------------------------------

UNO_BOARD = """board: hostile-uno
description: an UNO for hostile inputs
mcus:
  uno: {type: atmega328p, clock: 16MHz}
parts:
  host: {type: serial_host, flow: send_and_wait}
nets:
  host_rx: [uno.PD1, host.rx]
  host_tx: [host.tx, uno.PD0]
labels:
  led: uno.PB5
"""


def laughs(depth, width=10):
    """A YAML "billion laughs": width^depth nodes from a few lines."""
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x, x]"]
    for i in range(1, depth):
        lines.append(f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * width) + "]")
    return lines, f"*l{depth - 1}"


def board_with(extra_top="", description="plain", mcus=None, parts="", serial=None, labels=None, name="hostile"):
    """A board with a serial_host on USART0, or with `serial`: the deprecated
    serial section's entries (hostile shapes of it)."""
    mcus = mcus if mcus is not None else "  uno: {type: atmega328p, clock: 16MHz}"
    labels = labels if labels is not None else "  led: uno.PB5"
    text = extra_top + f"board: {name}\ndescription: {description}\nmcus:\n{mcus}\n"
    if serial is None:
        parts = "  host: {type: serial_host, flow: send_and_wait}" + ("\n" + parts if parts else "")
    if parts:
        text += "parts:\n" + parts + "\n"
    if serial is None:
        text += "nets:\n  host_rx: [uno.PD1, host.rx]\n  host_tx: [host.tx, uno.PD0]\n"
    else:
        text += f"serial:\n{serial}\n"
    text += f"labels:\n{labels}\n"
    return text


def scenario_with(board="board.yaml", firmware="{uno: fw.elf}", extra="", golden=None, steps="  - delay: 1ms"):
    text = f"name: hostile\nboard: {board}\nfirmware: {firmware}\ntime_limit: 1s\nsteps:\n{steps}\n" + extra
    if golden:
        text += f"golden: {golden}\n"
    return text


def elf_with_mmcu(elf_bytes, payload):
    """blink_timer1.elf with its .mmcu section's bytes replaced by `payload`
    (padded to the section's size with a VCD-file tag, which the bench ignores)."""
    data = bytearray(elf_bytes)
    e_shoff, = struct.unpack_from("<I", data, 0x20)
    e_shentsize, e_shnum, e_shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    def section(i):
        return struct.unpack_from("<IIIIIIIIII", data, e_shoff + i * e_shentsize)
    names_offset = section(e_shstrndx)[4]
    for i in range(e_shnum):
        sh = section(i)
        name = data[names_offset + sh[0]:data.index(0, names_offset + sh[0])].decode()
        if name == ".mmcu":
            offset, size = sh[4], sh[5]
            body = bytes(payload)
            if len(body) > size:
                raise ValueError("payload larger than .mmcu")
            rest = size - len(body)
            if rest == 1:
                raise ValueError("cannot pad one byte")
            if rest >= 2:
                body += bytes([12, rest - 2]) + bytes(rest - 2)  # AVR_MMCU_TAG_VCD_FILENAME
            data[offset:offset + size] = body
            return bytes(data)
    raise ValueError("no .mmcu section")


def tag(number, payload):
    return bytes([number, len(payload)]) + bytes(payload)


NAME_TAG = tag(1, b"atmega328p\0")


def freq_tag(hz):
    return tag(2, struct.pack("<I", hz))


# --- the cases -------------------------------------------------------------

def cases(fw):
    """Every hostile input, in a fixed order. `fw` maps firmware names to paths."""
    out = []
    blink = fw["blink_timer1"]
    echo = fw["uart_echo"]
    run_board = ["run", blink, "--board", "{w}/board.yaml", "--for", "1ms", "-q"]

    # YAML: alias cycles, in board files and scenarios, in sequences and maps.
    for where, key in (("description", "description"), ("labels", "labels"), ("serial", "serial"), ("top", "extra")):
        for shape, text in (("seq", "&x [*x]"), ("map", "&x {a: *x}"), ("deep", "&x [[1, [2, *x]]]")):
            if key == "description":
                board = board_with(description=text)
            elif key == "labels":
                board = board_with(labels=f"  led: {text}")
            elif key == "serial":
                board = board_with(serial=f"  host: {text}")
            else:
                board = board_with(extra_top=f"x: {text}\n")
            out.append(Case(f"yaml-cycle-board-{where}-{shape}", run_board, files={"board.yaml": board}, says="(a cycle)"))
            out.append(Case(f"yaml-cycle-scenario-{where}-{shape}", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
                            files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(),
                                   "s.yaml": scenario_with(extra=f"description: {text}\n" if key != "extra" else "")
                                   .replace("name: hostile", "name: hostile\nx: " + text if key == "extra" else "name: hostile")},
                            says="(a cycle)"))
    # YAML: expansion bombs where the bench walks or converts.
    for depth in (4, 6, 8, 10):
        lines, alias = laughs(depth)
        head = "\n".join(lines) + "\n"
        # 10^depth nodes: past 10^6 the expansion is refused; under it, the
        # laughs' own top-level keys (l0, l1, ...) are what is wrong.
        bomb = "nodes (aliases of aliases?)" if depth >= 6 else ""
        out.append(Case(f"yaml-laughs-board-description-{depth}", run_board, files={"board.yaml": head + board_with(description=alias)},
                        says=bomb or "board.yaml:1: unknown section 'l0'"))
        out.append(Case(f"yaml-laughs-board-params-{depth}", run_board,
                        files={"board.yaml": head + board_with(parts=f"  sw: {{type: limit_switch, bounce: {alias}}}")},
                        says=bomb or "board.yaml:1: unknown section 'l0'"))
        out.append(Case(f"yaml-laughs-board-top-{depth}", run_board, files={"board.yaml": head + board_with(extra_top=f"y: {alias}\n")},
                        says=bomb or "board.yaml:1: unknown section 'l0'"))
        out.append(Case(f"yaml-laughs-scenario-{depth}", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
                        files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(),
                               "s.yaml": head + scenario_with(extra=f"description: {alias}\n")},
                        says=bomb or "s.yaml:1: unknown key 'l0'"))
    # YAML: nesting.
    for depth in (100, 1000, 20000):
        out.append(Case(f"yaml-nesting-{depth}", run_board,
                        files={"board.yaml": board_with(description="[" * depth + "]" * depth)},
                        says="nested more than 64 levels deep" if depth == 100 else "board.yaml:2: YAML syntax error"))
    # YAML of the wrong shape, section by section.
    shapes = {"list": "[a, b]", "scalar": "hello", "number": "42", "null": "~", "nested": "{a: {b: [c]}}", "empty-map": "{}"}
    sections = {"mcus": "\n  uno: {type: atmega328p, clock: 16MHz}", "parts": " {}", "nets": " {}",
                "serial": " {}", "labels": "\n  led: uno.PB5"}
    for section in sections:
        for shape, text in shapes.items():
            board = "board: hostile\n" + "".join(
                f"{name}: {text if name == section else value.strip() if value.startswith(' ') else value}\n"
                for name, value in sections.items())
            # An empty or null parts, nets, serial or labels section is a board without them.
            legal = section != "mcus" and shape in ("null", "empty-map")
            # {a: {b: [c]}}: a map, so the error is about what is inside it.
            nested = {"mcus": "MCU 'a': unknown key 'b'", "parts": "parameter b must be a single value",
                      "nets": "net 'a' must list at least two endpoints", "serial": "b must be a single value",
                      "labels": "a net endpoint must be a single value"}
            wrong_shape = {"mcus": "the board needs an 'mcus' map", "parts": "'parts' must be a map", "nets": "'nets' must be a map",
                           "serial": "'serial' must be a map", "labels": "'labels' must be a map"}
            says = "" if legal else nested[section] if shape == "nested" else wrong_shape[section]
            out.append(Case(f"yaml-shape-{section}-{shape}", run_board, expect=0 if legal else 2, files={"board.yaml": board},
                            says=says))
    for entry, text, says in (("serial-port-list", "  host: [mcu, uno]", "serial port 'host' must be a map"),
                              ("serial-port-scalar", "  host: uno", "serial port 'host' must be a map"),
                              ("serial-port-nested", "  host: {mcu: [uno], usart: 0}", "mcu must be a single value")):
        out.append(Case(f"yaml-shape-{entry}", run_board, files={"board.yaml": board_with(serial=text)}, says=says))
    for entry, text, says in (("mcu-list", "  uno: [atmega328p, 16MHz]", "MCU 'uno' must be a map"),
                              ("mcu-scalar", "  uno: atmega328p", "MCU 'uno' must be a map"),
                              ("mcu-type-list", "  uno: {type: [atmega328p], clock: 16MHz}", "type must be a single value")):
        out.append(Case(f"yaml-shape-{entry}", run_board, files={"board.yaml": board_with(mcus=text)}, says=says))
    for entry, text, says in (("part-list", "  sw: [limit_switch]", "part 'sw' must be a map"),
                              ("part-scalar", "  sw: limit_switch", "part 'sw' must be a map"),
                              ("part-param-map", "  sw: {type: limit_switch, bounce: {a: 1}}", "parameter bounce must be a single value")):
        out.append(Case(f"yaml-shape-{entry}", run_board, files={"board.yaml": board_with(parts=text)}, says=says))
    scenario_says = {"steps-map": "'steps' is a list", "steps-scalar": "'steps' is a list",
                     "step-list": "each step is one 'kind: value' entry", "expect-map": "'expect' is a list",
                     "firmware-list": "the scenario needs 'firmware: {mcu: name-or-path}'",
                     "tolerances-map": "'tolerances' is a list"}
    for entry, text in (("steps-map", "steps: {delay: 1ms}"), ("steps-scalar", "steps: delay"),
                        ("step-list", "steps:\n  - [delay, 1ms]"), ("expect-map", "expect: {findings: 0}"),
                        ("firmware-list", "firmware: [fw.elf]"), ("tolerances-map", "tolerances: {signals: x}")):
        scenario = scenario_with().replace("steps:\n  - delay: 1ms\n", "")
        if entry.startswith("firmware"):
            scenario = scenario.replace("firmware: {uno: fw.elf}\n", "")
        out.append(Case(f"yaml-shape-scenario-{entry}", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
                        files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(), "s.yaml": scenario + text + "\n"},
                        says=scenario_says[entry]))
    # Names and identifiers: empty, control characters, escape sequences.
    for label, name in (("empty", "''"), ("newline", '"a\\nb"'), ("ansi", '"\\e[31mred\\e[0m"'), ("space", '"a b"'),
                        ("long", "x" * 300), ("unicode", '"\u00e9t\u00e9"')):
        out.append(Case(f"name-board-{label}", run_board, files={"board.yaml": board_with(name=name)},
                        says="is not 1 to 64 letters, digits"))
        # A type that names no MCU: the ELF (an ATmega328P's) does not match it.
        out.append(Case(f"name-mcu-type-{label}", run_board,
                        files={"board.yaml": board_with(mcus=f"  uno: {{type: {name}, clock: 16MHz}}")},
                        says="missing 'type'" if label == "empty" else "built for atmega328p, but"))
        # A long name is a name (only board names have a length limit); its switch has no axis.
        out.append(Case(f"name-part-{label}", run_board,
                        files={"board.yaml": board_with(parts=f"  {name}: {{type: limit_switch}}")},
                        says="port 'axis' is not connected" if label == "long" else "is not a valid part name"))
        out.append(Case(f"name-description-{label}", run_board, expect=0,
                        files={"board.yaml": board_with(description=name if label not in ("empty",) else "''")}))
    # Firmware configurations for `board from-config`: nesting past any
    # preprocessor's, a macro through itself, a 100 000-deep #if with no
    # #endif, NULs; read without a crash or a hang.
    deep = "(" * 100000 + "1" + ")" * 100000
    for label, text, expect, says in (
            ("deep-parens", f"#define MOTHERBOARD 33\n#define DEFAULT_AXIS_STEPS_PER_UNIT {{{deep},80,400,100}}\n", 0, ""),
            ("self-enabled", "#define MOTHERBOARD 33\n#define A ENABLED(A)\n#if ENABLED(A)\n#define DEFAULT_AXIS_STEPS_PER_UNIT {1,2,3,4}\n#endif\n",
             0, ""),
            ("unclosed-ifs", "#define MOTHERBOARD 33\n" + "#if 1\n" * 100000 + "#define DEFAULT_AXIS_STEPS_PER_UNIT {1,2,3,4}\n", 2,
             "Configuration.h:258: #if nested more than 256 deep"),
            ("nul-bytes", "#define MOTHERBOARD 33\n#define DEFAULT_AXIS_STEPS_PER_UNIT {1\x00,2,3,4}\n\x00\x00", 0, "")):
        out.append(Case(f"fwconfig-{label}", ["board", "from-config", "{w}/Configuration.h", "-o", "{w}/out.yaml"], expect=expect,
                        files={"Configuration.h": text}, says=says))
    # A board's text that the summary prints (the oracle's reason for giving
    # no home, said when dda_line's G28 ends the judging): escaped, never an
    # escape sequence on the terminal (the runner checks).
    out.append(Case("text-no-home-because-ansi",
                    ["run", fw["dda_line"], "--board", "{w}/board.yaml", "--gcode", "{w}/job.gcode", "--for", "5s"], expect=0,
                    files={"board.yaml": "board: t\nextends: arduino-uno-cnc-shield-v3\nparts:\n"
                                         "  host: {type: serial_host, flow: send_and_wait, family: generic}\n"
                                         "  motion: {type: motion_oracle, no_home_because: \"a\\e[2Jb\\nc\"}\n",
                           "job.gcode": "G28\n"},
                    stdout_has="(a\\x1b[2Jb\\x0ac)"))
    for label, value in (("newline", "1\nms"), ("ansi", "1\x1b[2Jms"), ("nul-like", "1ms\x7f")):
        out.append(Case(f"cli-for-{label}", ["run", blink, "--for", value, "-q"], says="--for: unknown unit"))
        out.append(Case(f"cli-mcu-{label}", ["run", blink, "--mcu", value, "-q"], says="unknown MCU"))
        out.append(Case(f"cli-elf-{label}", ["run", "{w}/fw" + value + ".elf", "-q"], says="no such file"))
        out.append(Case(f"cli-trace-{label}", ["run", blink, "--trace", value, "--for", "1ms", "-q"], says="--trace: bad pin name"))
        out.append(Case(f"cli-trace-only-{label}", ["run", blink, "--trace-only", value, "--for", "1ms", "-q"],
                        says="--trace-only: bad pin name"))
    out.append(Case("cli-trace-and-trace-only", ["run", blink, "--trace", "PB5", "--trace-only", "PB1", "--for", "1ms", "-q"],
                    says="--trace excludes --trace-only"))
    out.append(Case("cli-vcd-format-unknown", ["run", blink, "--vcd-format", "wide", "--vcd", "{w}/o.vcd", "--for", "1ms", "-q"],
                    says="--vcd-format: wide not in"))
    out.append(Case("cli-trace-duplicate", ["run", blink, "--trace", "PB5,PB5,pb5", "--vcd", "{w}/o.vcd", "--for", "1ms", "-q"],
                    expect=0))
    # Clocks outside 1 Hz .. 64 MHz, in boards.
    for clock in ("0Hz", "64000001", "2147483648", "4294967295", "1e300Hz", "-16MHz", "nan"):
        out.append(Case(f"board-clock-{clock}", run_board,
                        files={"board.yaml": board_with(mcus=f"  uno: {{type: atmega328p, clock: {clock}}}")},
                        says=f"clock: '{clock}' is not " + ("finite" if clock == "nan" else "a whole number of Hz from 1 Hz to 64 MHz")))
    # Too many MCUs.
    for count in (17, 200):
        mcus = "\n".join(f"  m{i}: {{type: atmega328p, clock: 16MHz}}" for i in range(count))
        out.append(Case(f"board-{count}-mcus", run_board,
                        files={"board.yaml": f"board: many\nmcus:\n{mcus}\n"}, says="a board holds at most 16"))
    # Physics out of any range.
    for label, heater, plant in (
            ("tiny-resistance", "resistance: 1e-300ohm, supply: 12V", "heat_capacity: 16J/K"),
            ("kilovolt-tiny-block", "resistance: 1ohm, supply: 1000V", "heat_capacity: 0.001J/K"),
            ("kilovolt-small-block", "resistance: 0.01ohm, supply: 1000V", "heat_capacity: 1J/K")):
        parts = (f"  plant: {{type: thermal_plant, preset: custom, {plant}, ambient_conductance: 0.1W/K, sensor_time_constant: 1s}}\n"
                 f"  heat: {{type: heater, preset: custom, {heater}}}")
        board = board_with(parts=parts).replace("labels:\n", "  body: [heat.body, plant.body]\n  gate: [uno.PD6, heat.gate]\nlabels:\n")
        out.append(Case(f"physics-{label}", run_board, files={"board.yaml": board},
                        says="is outside 0.001" if label == "tiny-resistance" else "not a physical combination"))

    # Input files that are not regular files, or too large.
    specials = {"fifo": None, "dev-zero": "/dev/zero", "dev-urandom": "/dev/urandom", "dir": None, "missing": "{w}/nope"}
    roles = {
        "board": lambda p: ["run", blink, "--board", p, "--for", "1ms", "-q"],
        "gcode": lambda p: ["run", echo, "--board", "{w}/board.yaml", "--gcode", p, "--for", "10ms", "-q"],
        "uart-in-board": lambda p: ["run", echo, "--board", "{w}/board.yaml", "--uart-in", p, "--for", "1ms", "-q"],
        "uart-in-bare": lambda p: ["run", echo, "--uart-in", p, "--for", "1ms", "-q"],
        "scenario": lambda p: ["check", p],
        "elf": lambda p: ["run", p, "--for", "1ms", "-q"],
        "dxf": lambda p: ["cam", p, "-o", "{w}/out.nc"],
        "golden": lambda p: ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
        "bootloader": lambda p: ["run", blink, "--board", "{w}/bl.yaml", "--for", "1ms", "-q"],
    }
    for role, make_args in roles.items():
        for kind, path in specials.items():
            files = {"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read()}
            fifos, dirs = (), ()
            target = path
            says = {"fifo": "is a FIFO", "dev-zero": "character device", "dev-urandom": "character device",
                    "dir": "folder", "missing": "no such"}[kind]
            if kind == "fifo":
                target, fifos = "{w}/special", ("special",)
            elif kind == "dir":
                target, dirs = "{w}/special", ("special",)
            if role == "golden":
                files["s.yaml"] = scenario_with(golden=target.replace("{w}/", ""))
            if role == "bootloader":
                files["bl.yaml"] = board_with(mcus=f"  uno: {{type: atmega328p, clock: 16MHz, bootloader: {target.replace('{w}', '.')}, "
                                                    "fuses: {low: 0xFF, high: 0xDE, extended: 0xFD}}")
            # A golden that is not there fails the scenario (exit 1: "create it with golden update").
            expect = 1 if role == "golden" and kind == "missing" else 2
            out.append(Case(f"input-{role}-{kind}", make_args(target), expect=expect, files=files, fifos=fifos, dirs=dirs,
                            says=says if expect == 2 else ""))
        # A sparse file far over the role's cap (the ELF one is legal: see below).
        if role not in ("elf",):
            files = {"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read()}
            target = "{w}/huge"
            if role == "golden":
                files["s.yaml"] = scenario_with(golden="huge")
            if role == "bootloader":
                files["bl.yaml"] = board_with(mcus="  uno: {type: atmega328p, clock: 16MHz, bootloader: ./huge, "
                                                   "fuses: {low: 0xFF, high: 0xDE, extended: 0xFD}}")
            out.append(Case(f"input-{role}-sparse-2GiB", make_args(target), files=files, sparse={"huge": (b"x", 2 << 30)},
                            says="is more than a"))
    # A 2 GiB sparse ELF: blink_timer1.elf followed by zeros - a valid ELF, read
    # only where its headers point: it runs.
    out.append(Case("input-elf-sparse-2GiB", ["run", "{w}/huge.elf", "--for", "1ms", "-q"], expect=0,
                    sparse={"huge.elf": (open(blink, "rb").read(), 2 << 30)}))
    out.append(Case("input-uart-in-stdin-pipe", ["run", echo, "--uart-in", "-", "--for", "1ms", "-q"], expect=0))

    # Outputs: two outputs on one file, an output on an input, empty names.
    for label, extra in (
            ("vcd-is-uart-out", ["--vcd", "{w}/x", "--uart-out", "{w}/x"]),
            ("report-is-vcd", ["--vcd", "{w}/x.vcd", "--report", "{w}/x.vcd"]),
            ("vcd-named-gtkw", ["--vcd", "{w}/x.gtkw"]),
            ("uart-out-on-gtkw", ["--vcd", "{w}/x.vcd", "--uart-out", "{w}/x.gtkw"]),
            ("uart-out-twice-hardlink", ["--vcd", "{w}/a.vcd", "--uart-out", "{w}/hard"]),
            ("vcd-empty", ["--vcd", ""]),
            ("report-empty", ["--report", ""]),
            ("uart-out-dir", ["--uart-out", "{w}/d"]),
            ("vcd-on-board", ["--vcd", "{w}/board.yaml"]),
            ("uart-out-on-elf", ["--uart-out", "{w}/fw.elf"]),
            ("vcd-on-uart-in", ["--uart-in", "{w}/in.txt", "--vcd", "{w}/in.txt"])):
        def link(folder):
            if os.path.exists(os.path.join(folder, "a.gtkw")):
                return
            open(os.path.join(folder, "a.gtkw"), "w").write("keep")
            os.link(os.path.join(folder, "a.gtkw"), os.path.join(folder, "hard"))
        out.append(Case(f"output-{label}", ["run", "{w}/fw.elf", "--board", "{w}/board.yaml", "--for", "1ms", "-q"] + extra,
                        files={"board.yaml": UNO_BOARD, "fw.elf": open(echo, "rb").read(), "in.txt": "hello"},
                        dirs=("d",), check_files=("board.yaml", "fw.elf", "in.txt", "a.gtkw", "hard"),
                        setup=link if "hardlink" in label else None,
                        says="an empty value" if "empty" in label else "folder" if "dir" in label else "is also"))
    out.append(Case("output-pty-link-on-file", ["run", "{w}/fw.elf", "--board", "{w}/board.yaml", "--pty", "host",
                                                 "--pty-link", "{w}/victim.txt", "--for", "1ms", "-q"],
                    files={"board.yaml": UNO_BOARD, "fw.elf": open(echo, "rb").read(), "victim.txt": "keep"},
                    check_files=("victim.txt",), says="not a link to a pseudo-terminal"))
    dxf = open(os.path.join(ARGS.source, "tests/fixtures/dxf", sorted(os.listdir(os.path.join(ARGS.source, "tests/fixtures/dxf")))[0]), "rb").read()
    out.append(Case("output-cam-own-input", ["cam", "{w}/plot.nc"], files={"plot.nc": dxf}, check_files=("plot.nc",), says="is also read"))
    out.append(Case("output-cam-o-input", ["cam", "{w}/d.dxf", "-o", "{w}/d.dxf"], files={"d.dxf": dxf}, check_files=("d.dxf",),
                    says="is also read"))
    cnc = fw["cnc2axis"]
    out.append(Case("output-run-dxf-nc-on-drawing", ["run", cnc, "--board", "cnc2axis-seed002", "--dxf", "{w}/d.dxf",
                                                     "--nc", "{w}/d.dxf", "-q"], files={"d.dxf": dxf}, check_files=("d.dxf",),
                    says="is also read"))
    # golden update writes goldens only, where goldens live.
    for label, golden, expect in (("outside-txt", "../sentinel/victim.txt", 2), ("outside-timeline", "../sentinel/victim.timeline", 2),
                                  ("inside-not-golden", "notes.timeline", 2), ("absolute", "/tmp/avrbench-hostile-victim.timeline", 2)):
        out.append(Case(f"golden-update-{label}", ["golden", "update", "{w}/scen/s.yaml", "--firmware-dir", "{w}/scen"], expect=expect,
                        files={"scen/board.yaml": UNO_BOARD, "scen/fw.elf": open(blink, "rb").read(),
                               "scen/s.yaml": scenario_with(golden=golden), "scen/notes.timeline": "my notes\n",
                               "sentinel/victim.txt": "keep", "sentinel/victim.timeline": "keep"},
                        check_files=("sentinel/victim.txt", "sentinel/victim.timeline", "scen/notes.timeline"),
                        says="not a golden timeline" if label == "inside-not-golden" else "golden update writes only"))
    # The documented `board: <standard name>` from another folder.
    out.append(Case("scenario-standard-board-elsewhere", ["check", "{w}/scen/s.yaml", "--firmware-dir", "{w}/scen"], expect=0,
                    files={"scen/fw.elf": open(blink, "rb").read(), "scen/s.yaml": scenario_with(board="arduino-uno")},
                    cwd="elsewhere", dirs=("elsewhere",)))

    # Golden timelines that are malformed or that claim far more than a run.
    head = ("avrbench-timeline 1\nbench 0.1.0\nend 16001 16000000\nsignal uno.PB5 wire 1 16000000\n"
            "signal uno.PB1 wire 1 16000000\nsignal uno.uart0_tx bus 8 16000000\n\n@uno.PB5\n0 0\n")
    # The head is 9 lines: a body's error is on line 10. The repeat bomb's
    # changes fall on cycles 1, 2, ...: the first past the end (16001) is 16002.
    golden_says = {"two-changes-on-a-line": "g.timeline:10: '+15' after a change", "value-missing": "g.timeline:10: '+17' has no value",
                   "junk-after": "g.timeline:10: 'junk' after a change", "repeat-odd": "g.timeline:10: repeat block: '+5' has no value",
                   "past-end": "g.timeline:10: cycle 99999 is after the timeline's end",
                   "repeat-bomb-past-end": "g.timeline:10: cycle 16002 is after the timeline's end",
                   "signal-missing-clock": "g.timeline:5: 'signal' needs scope.name, kind, width and clock"}
    for label, body, expect in (
            ("two-changes-on-a-line", "+17 0 +15 1\n", 2), ("value-missing", "+17\n", 2), ("junk-after", "+17 1 junk\n", 2),
            ("repeat-odd", "*3 +5 1 +5\n", 2), ("past-end", "+99999 1\n", 2),
            ("repeat-bomb-past-end", "*24999990 +1 0 +1 1\n", 2),
            ("signal-missing-clock", "", 2)):
        text = head + body
        if label == "signal-missing-clock":
            text = text.replace("signal uno.PB1 wire 1 16000000", "signal uno.PB1 wire 1")
        out.append(Case(f"golden-{label}", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"], expect=expect,
                        files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(),
                               "s.yaml": scenario_with(golden="g.timeline"), "g.timeline": text}, says=golden_says[label]))
    # A repeat inside the timeline's end but far past the run: read no further
    # than the run went, so it fails (exit 1) at once.
    big_end = head.replace("end 16001 16000000", "end 1000000000000 16000000")
    out.append(Case("golden-repeat-bomb-past-run", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"], expect=1,
                    files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(),
                           "s.yaml": scenario_with(golden="g.timeline"), "g.timeline": big_end + "*24999990 +1 0 +1 1\n"}))

    # Malformed or out-of-range .mmcu sections.
    blink_bytes = open(blink, "rb").read()
    for label, payload, expect in (
            ("freq-0", NAME_TAG + freq_tag(0), 2), ("freq-64000001", NAME_TAG + freq_tag(64000001), 2),
            ("freq-2^31", NAME_TAG + freq_tag(1 << 31), 2), ("freq-2^32-1", NAME_TAG + freq_tag((1 << 32) - 1), 2),
            ("unknown-tag", NAME_TAG + freq_tag(16000000) + tag(18, b"\x0f"), 2),
            ("command-0xffff", NAME_TAG + freq_tag(16000000) + tag(10, b"\xff\xff"), 2),
            ("console-0xffff", NAME_TAG + freq_tag(16000000) + tag(11, b"\xff\xff"), 2),
            ("vcd-trace-40", NAME_TAG + freq_tag(16000000) + tag(14, bytes(40)), 2),
            ("tag-overruns", NAME_TAG + freq_tag(16000000) + bytes([2, 200, 0]), 2),
            ("name-unterminated", tag(1, b"atmega328p") + freq_tag(16000000), 2),
            ("fuse-tags-ignored", NAME_TAG + freq_tag(16000000) + tag(6, b"\xff") + tag(7, b"\xde"), 0),
            ("vcd-trace-35-ignored", NAME_TAG + freq_tag(16000000) + tag(14, bytes(35)), 0)):
        try:
            elf = elf_with_mmcu(blink_bytes, payload)
        except ValueError:
            continue
        out.append(Case(f"mmcu-{label}", ["run", "{w}/m.elf", "--for", "1ms", "-q"], expect=expect, files={"m.elf": elf},
                        says=".mmcu section" if expect == 2 else ""))
    # Round three (issue 62): outputs through links and over read-only files.
    def link_to_victim(folder):
        os.symlink(os.path.join(folder, "victim.txt"), os.path.join(folder, "err.vcd"))
    out.append(Case("out-vcd-symlink", ["run", blink, "--for", "1ms", "--vcd", "{w}/err.vcd", "-q"], files={"victim.txt": "keep me\n"},
                    setup=link_to_victim, says="is a symbolic link"))
    # The issue's /dev/stderr, made in the case's folder: a regression must not
    # replace the machine's own link.
    out.append(Case("out-vcd-link-to-stderr", ["run", blink, "--for", "1ms", "--vcd", "{w}/err.vcd", "-q"],
                    setup=lambda folder: os.symlink("/proc/self/fd/2", os.path.join(folder, "err.vcd")), says="is a symbolic link"))
    out.append(Case("out-vcd-read-only", ["run", blink, "--for", "1ms", "--vcd", "{w}/ro.vcd", "-q"], files={"ro.vcd": "mine\n"},
                    setup=lambda folder: os.chmod(os.path.join(folder, "ro.vcd"), 0o400), says="is read-only"))
    # Raw bytes into a bit-level serial port: streamed (not a scheduled event
    # per bit up front), and counted as delivered at their stop bits: 10 ms
    # at 9600 baud is 9 whole frames of 1.04 ms.
    bit_board = ("board: bitlevel\nmcus:\n  uno: {type: atmega328p, clock: 16MHz}\nparts:\n  host: {type: serial_host, baud: 9600}\n"
                 "nets:\n  host_rx: [uno.PB2, host.rx]\n  host_tx: [host.tx, uno.PB3]\n")
    for label, size in (("4MiB", 4 << 20), ("16MiB", 16 << 20)):
        out.append(Case(f"uart-in-bit-level-{label}", ["run", blink, "--board", "{w}/b.yaml", "--uart-in", "{w}/in.bin", "--for", "10ms"],
                        expect=0, files={"b.yaml": bit_board, "in.bin": bytes(range(256)) * (size // 256)},
                        stdout_has="0 bytes from firmware, 9 bytes to firmware"))
    # Fuzz arguments, checked before any work.
    fuzz = ["fuzz", "--elf", blink, "--board", "{w}/board.yaml", "--for", "2s"]
    for label, extra, says in (("runs-negative", ["--runs", "-1"], "is not a count of executions"),
                               ("runs-2^64", ["--runs", "18446744073709551616"], "is not a count of executions"),
                               ("jobs-0", ["--jobs", "0"], "is not from 1 to 64"),
                               ("bound-0", ["--bound", "0s"], "is under 1 ms"),
                               ("out-file", ["--out", "{w}/board.yaml"], "is not a folder"),
                               ("out-elf", ["--out", blink], "is not a folder"),
                               ("out-dev-full", ["--out", "/dev/full"], "is not a folder"),
                               ("out-missing-parent", ["--out", "{w}/no/such/out"], "is not a writable folder")):
        out.append(Case(f"fuzz-{label}", fuzz + extra, files={"board.yaml": UNO_BOARD}, says=says))
    def corpus_loop(folder):
        os.makedirs(os.path.join(folder, "corpus"))
        os.symlink("loop", os.path.join(folder, "corpus", "loop"))
    out.append(Case("fuzz-corpus-symlink-loop", fuzz + ["--runs", "5", "--corpus", "{w}/corpus", "--out", "{w}/out"], expect=2,
                    files={"board.yaml": UNO_BOARD}, setup=corpus_loop, says="holds no files"))
    # A golden of nothing, a line timeout of nothing, a vector past the MCU's.
    out.append(Case("golden-header-only", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
                    files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(), "g.txt": "avrbench-timeline 1\n",
                           "s.yaml": scenario_with(golden="g.txt")}, says="holds no signal"))
    out.append(Case("serial-host-line-timeout-tiny", run_board,
                    files={"board.yaml": UNO_BOARD.replace("{type: serial_host, flow: send_and_wait}",
                                                           "{type: serial_host, line_timeout: 1e-13s}")},
                    says="at least 100us"))
    out.append(Case("scenario-isr-vector-26", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
                    files={"board.yaml": UNO_BOARD, "fw.elf": open(blink, "rb").read(),
                           "s.yaml": scenario_with(extra="expect:\n  - isr: {vector: 26, min_runs: 1}\n")},
                    says="has interrupt vectors 1 to 25"))
    out.append(Case("scenario-firmware-dev-zero", ["check", "{w}/s.yaml", "--firmware-dir", "{w}"],
                    files={"board.yaml": UNO_BOARD, "s.yaml": scenario_with(firmware="{uno: /dev/zero}")},
                    says="is a character device"))
    # One line for one problem: nothing announced before the error.
    out.append(Case("gdb-unknown-mcu", ["run", blink, "--board", "{w}/board.yaml", "--gdb", "nope=0", "--for", "1ms"],
                    files={"board.yaml": UNO_BOARD}, says="no MCU named 'nope'"))
    out.append(Case("serial-both-shapes", run_board, files={"board.yaml": UNO_BOARD + "serial:\n  other: {mcu: uno, usart: 0}\n"},
                    says="already on another net"))

    # One trailing byte after the last tag: the section is one byte longer
    # than its tags, which padding cannot express; cut it instead.
    return out


# --- the Python module, the GDB server and signals (scripts driving them) ------

# Each script gets the case's folder as sys.argv[1] and exits 0 when the bench
# behaved as documented (an AssertionError otherwise); the runner's checks
# (CPU time, memory, sanitizer reports, files left as they were) apply to it
# and to the avrbench it starts.
PY_HEAD = """
import os, signal, socket, subprocess, sys, threading, time
import avrbench
w = sys.argv[1]
fw = os.environ["AVRBENCH_FIRMWARE_DIR"]
cli = os.environ["AVRBENCH_CLI"]
def raises(kind, fn, says=""):
    try:
        fn()
    except kind as e:
        assert says in str(e), (says, str(e))
        return
    raise AssertionError(f"{fn} did not raise {kind.__name__}")
"""


def driver_cases(fw):
    out = []
    blink = fw["blink_timer1"]
    out.append(Case("python-vcd-over-the-elf", None, expect=0, files={"fw.elf": open(blink, "rb").read()}, python=PY_HEAD + r"""
raises(avrbench.BadInput, lambda: avrbench.Bench("arduino-uno", w + "/fw.elf", vcd=w + "/fw.elf"), "is also read as")
"""))
    out.append(Case("python-vcd-and-report-one-file", None, expect=0, python=PY_HEAD + r"""
raises(avrbench.BadInput, lambda: avrbench.Bench("arduino-uno", fw + "/blink_timer1.elf", vcd=w + "/x", report=w + "/x"),
       "give each output a file of its own")
"""))
    out.append(Case("python-vcd-symlink", None, expect=0, files={"victim.txt": "keep me\n"},
                    setup=lambda folder: os.symlink(os.path.join(folder, "victim.txt"), os.path.join(folder, "l.vcd")),
                    python=PY_HEAD + r"""
raises(avrbench.BadInput, lambda: avrbench.Bench("arduino-uno", fw + "/blink_timer1.elf", vcd=w + "/l.vcd"), "symbolic link")
"""))
    # expect() on a 200 kB line: no recursion, no exponential time (RE2).
    out.append(Case("python-expect-200kB-line", None, expect=0, python=PY_HEAD + r"""
b = avrbench.Bench("arduino-uno", fw + "/uart_echo.elf")
port = b.serial()
port.write(b"a" * 200000 + b"\n")
for pattern, size in ((".*x", 200000), ("^a*b$", 200000), ("(a|a)*b", 200000)):
    raises(avrbench.Timeout, lambda: port.expect(pattern, timeout="30s"), "no line matching")
raises(avrbench.BadInput, lambda: port.expect("(unclosed", timeout="1ms"), "is not a regular expression")
"""))
    # Ctrl-C during a long run: KeyboardInterrupt soon after, the outputs valid.
    # The run is a million simulated seconds (minutes of wall time even at
    # this firmware's ~2 500x real time), so the SIGINT at 0.5 s comes first
    # however fast the machine is.
    out.append(Case("python-sigint-in-run-for", None, expect=0, python=PY_HEAD + r"""
b = avrbench.Bench("arduino-uno", fw + "/blink_timer1.elf", vcd=w + "/i.vcd")
def interrupt():
    time.sleep(0.5)
    global sent
    sent = time.monotonic()
    os.kill(os.getpid(), signal.SIGINT)
threading.Thread(target=interrupt).start()
try:
    b.run_for("1000000s")
    raise AssertionError("run_for ended without the KeyboardInterrupt")
except KeyboardInterrupt:
    late = time.monotonic() - sent
assert late < 1.0, f"KeyboardInterrupt {late:.2f} s after SIGINT"
assert 0 < b.now < 1000000
b.close()
assert open(w + "/i.vcd").read(200).startswith("$"), "the VCD of the interrupted run is not a VCD"
"""))
    out.append(Case("python-event-cap-is-an-error", None, expect=0, python=PY_HEAD + r"""
b = avrbench.Bench("arduino-uno", fw + "/blink_timer1.elf", max_events=5000)
raises(avrbench.BadInput, lambda: b.run_for("30000s"), "the run recorded more than 5000")
"""))
    out.append(Case("python-closed-bench", None, expect=0, python=PY_HEAD + r"""
b = avrbench.Bench("arduino-uno", fw + "/blink_timer1.elf")
port, mcu, part = b.serial(), b.mcu(), None
b.close()
raises(avrbench.BadInput, lambda: b.run_for("1ms"), "closed")
raises(avrbench.BadInput, lambda: port.write(b"x"), "closed")
raises(avrbench.BadInput, lambda: mcu.pc, "closed")
raises(avrbench.BadInput, lambda: b.run_until_idle(max="1ms"), "closed")
assert issubclass(avrbench.BadInput, avrbench.Error) and issubclass(avrbench.Timeout, avrbench.Error)
"""))
    # The GDB server: 2 MB while it waits for an acknowledgement costs its
    # length (the runner's 5 s of CPU), and a client that goes away ends the run.
    out.append(Case("gdb-2MB-while-waiting-for-ack-and-client-gone", None, expect=0, python=PY_HEAD + r"""
p = subprocess.Popen([cli, "run", fw + "/blink_timer1.elf", "--gdb", "0", "--for", "1000s", "-q"], stdout=subprocess.DEVNULL,
                     stderr=subprocess.PIPE, text=True)
line = p.stderr.readline()  # "gdb: MCU (first) waits for avr-gdb on 127.0.0.1:PORT ..."
port = int(line.split("127.0.0.1:")[1].split()[0])
s = socket.create_connection(("127.0.0.1", port))
s.sendall(b"$?#3f")
s.sendall(b"x" * 2000000)
s.sendall(b"+$c#63")
time.sleep(0.5)
s.close()
started = time.monotonic()
p.wait(timeout=10)
assert time.monotonic() - started < 5, "the run went on after its debugger left"
"""))
    # SIGTERM to a fuzz campaign: passed to the engine, exit 130 at once.
    out.append(Case("fuzz-sigterm", None, expect=0, files={"board.yaml": UNO_BOARD}, python=PY_HEAD + r"""
p = subprocess.Popen([cli, "fuzz", "--elf", fw + "/uart_echo.elf", "--board", w + "/board.yaml", "--for", "120s",
                      "--out", w + "/out"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
time.sleep(3)
p.send_signal(signal.SIGTERM)
started = time.monotonic()
code = p.wait(timeout=20)
assert code == 130, code
assert time.monotonic() - started < 2, "SIGTERM not honoured at once"
"""))
    return out


# --- running -----------------------------------------------------------------

def digest(path):
    try:
        with open(path, "rb") as f:
            return hashlib.sha256(f.read(1 << 20)).hexdigest() + str(os.path.getsize(path))
    except OSError as e:
        return "missing:" + type(e).__name__


def prepare(case, folder):
    if os.path.exists(folder):
        shutil.rmtree(folder)
    os.makedirs(folder)
    for rel, content in case.files.items():
        path = os.path.join(folder, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(content.encode() if isinstance(content, str) else content)
    for rel in case.dirs:
        os.makedirs(os.path.join(folder, rel), exist_ok=True)
    for rel in case.fifos:
        os.mkfifo(os.path.join(folder, rel))
    for rel, (prefix, size) in case.sparse.items():
        with open(os.path.join(folder, rel), "wb") as f:
            f.write(prefix)
            f.truncate(size)
    if case.setup:
        case.setup(folder)


def run(case):
    folder = os.path.join(ARGS.work, case.name)
    prepare(case, folder)
    watched = [os.path.join(folder, p) for p in case.check_files] + [os.path.join(folder, p) for p in case.files]
    before = {p: digest(p) for p in watched if not any(p.endswith(f) for f in case.fifos)}
    env = dict(os.environ, AVRBENCH_FIRMWARE_DIR=ARGS.firmware_dir)
    if case.python is None:
        argv = [ARGS.cli] + [a.replace("{w}", folder) for a in case.args]
    else:
        argv = ["/usr/bin/python3", "-c", case.python, folder]
        env.update(PYTHONPATH=ARGS.python, AVRBENCH_CLI=ARGS.cli, AVRBENCH_SOURCE=ARGS.source)
    cwd = os.path.join(folder, case.cwd) if case.cwd else folder
    with open(os.path.join(folder, ".stdout"), "wb") as out, open(os.path.join(folder, ".stderr"), "wb") as err:
        started = time.monotonic()
        def limit():
            if ARGS.address_space_mb:  # for an unsanitized CLI only: ASan reserves terabytes of address space
                resource.setrlimit(resource.RLIMIT_AS, (ARGS.address_space_mb << 20, ARGS.address_space_mb << 20))
        process = subprocess.Popen(argv, stdin=subprocess.PIPE if case.args and "-" in case.args else subprocess.DEVNULL, stdout=out,
                                   stderr=err, cwd=cwd, env=env, start_new_session=True, preexec_fn=limit)
        if process.stdin:
            try:
                process.stdin.write(b"G28\n")
                process.stdin.close()
            except BrokenPipeError:
                pass  # the CLI ended without reading: its exit code tells
        status = rusage = None
        while True:
            pid, status, rusage = os.wait4(process.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() - started > ARGS.wall_guard:
                os.killpg(process.pid, signal.SIGKILL)
                pid, status, rusage = os.wait4(process.pid, 0)
                return case, [f"hang: still running after {ARGS.wall_guard:.0f} s of wall time"]
            time.sleep(0.01)
    code = os.waitstatus_to_exitcode(status)
    stdout = open(os.path.join(folder, ".stdout"), "rb").read().decode("utf-8", "replace")
    stderr = open(os.path.join(folder, ".stderr"), "rb").read().decode("utf-8", "replace")
    problems = []
    cpu = rusage.ru_utime + rusage.ru_stime
    if cpu > CPU_LIMIT_S:
        problems.append(f"{cpu:.1f} s of CPU time (limit {CPU_LIMIT_S:.0f} s)")
    if rusage.ru_maxrss > RSS_LIMIT_KB:
        problems.append(f"peak RSS {rusage.ru_maxrss // 1024} MB (limit {RSS_LIMIT_KB // 1024} MB)")
    for marker in ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:", "internal error"):
        if marker in stderr:
            problems.append(f"'{marker}' on stderr")
    if code < 0:
        problems.append(f"killed by signal {-code}")
    elif code != case.expect:
        problems.append(f"exit {code}, expected {case.expect}")
    if case.expect == 2 and code == 2:
        lines = stderr.splitlines()
        if len(lines) != 1 or not (lines[0].startswith("avrbench: error: ") or lines[0].startswith("avrbench: usage error: ")):
            problems.append(f"stderr is not one 'avrbench: error:' line: {stderr[:300]!r}")
        elif not case.says:
            problems.append("an exit-2 case without a fragment of its error (says=): it would pass for any error")
        elif case.says not in lines[0]:
            problems.append(f"the error does not say '{case.says}'")
    if case.stdout_has and case.stdout_has not in stdout:
        problems.append(f"stdout does not hold '{case.stdout_has}'")
    if "\x1b" in stderr or "\x1b" in stdout:
        problems.append("an escape sequence reached the terminal")
    for p, d in before.items():
        if digest(p) != d:
            problems.append(f"{os.path.relpath(p, folder)} was modified")
    if os.path.exists("/tmp/avrbench-hostile-victim.timeline"):
        problems.append("/tmp/avrbench-hostile-victim.timeline was written")
        os.remove("/tmp/avrbench-hostile-victim.timeline")
    if problems:
        problems.append(f"command: {' '.join(argv)!r}; stderr: {stderr[:400]!r}")
    else:
        shutil.rmtree(folder, ignore_errors=True)  # passed: no scratch left (sparse files are 2 GiB of nothing)
    return case, problems


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cli", required=True)
    parser.add_argument("--firmware-dir", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--sample", type=int, default=0, help="run this many cases, a seeded sample (0: all)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--list", action="store_true")
    parser.add_argument("--only", default="", help="run the cases whose name contains this")
    parser.add_argument("--wall-guard", type=float, default=WALL_GUARD_S, help="seconds before a case counts as a hang")
    parser.add_argument("--python", default="",
                        help="the Python module's folder (build/python): the module's and the GDB server's cases run too")
    parser.add_argument("--address-space-mb", type=int, default=0,
                        help="cap each run's address space (protects the machine when trying an old, unsanitized CLI)")
    ARGS = parser.parse_args()
    ARGS.work = os.path.abspath(ARGS.work)
    ARGS.cli = os.path.abspath(ARGS.cli)
    ARGS.firmware_dir = os.path.abspath(ARGS.firmware_dir)
    ARGS.source = os.path.abspath(ARGS.source)
    fw = {}
    for name in ("blink_timer1", "uart_echo", "cnc2axis", "dda_line"):
        path = os.path.join(ARGS.firmware_dir, name + ".elf")
        # A missing ELF is a broken build, not a case to leave out quietly.
        if not os.path.exists(path):
            sys.exit(f"hostile: {path} is missing (build the firmware first)")
        fw[name] = path
    all_cases = cases(fw)
    driven = driver_cases(fw)
    if ARGS.python:
        ARGS.python = os.path.abspath(ARGS.python)
        all_cases += driven
    else:
        print(f"hostile inputs: {len(driven)} cases of the Python module, the GDB server and signals need --python "
              "(a build with the module); not run here")
    names = [c.name for c in all_cases]
    assert len(names) == len(set(names)), "case names repeat"
    chosen = [c for c in all_cases if ARGS.only in c.name]
    if ARGS.sample and ARGS.sample < len(chosen):
        chosen = random.Random(ARGS.seed).sample(chosen, ARGS.sample)
    if ARGS.list:
        for c in chosen:
            print(c.name, c.expect)
        return 0
    os.makedirs(ARGS.work, exist_ok=True)
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=ARGS.jobs) as pool:
        for case, problems in pool.map(run, chosen):
            if problems:
                failed += 1
                print(f"FAIL {case.name}: " + "; ".join(problems))
    print(f"hostile inputs: {len(chosen) - failed} of {len(chosen)} handled as documented "
          f"(exit codes, one-line errors, no sanitizer report, <= {CPU_LIMIT_S:.0f} s CPU, <= {RSS_LIMIT_KB // 1024} MB, no file modified)")
    return 1 if failed else 0


ARGS = None
if __name__ == "__main__":
    sys.exit(main())
