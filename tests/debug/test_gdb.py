#!/usr/bin/env python3
"""avr-gdb (Debian gdb-avr) in batch mode against `avrbench run --gdb`.

Every expected value comes from the firmware's source or from the ELF read
with binutils (avr-nm, avr-objdump), never from avrbench's own output:
firmware/gdb_target/main.c says ticks holds 3 * (n - 1) on the n-th entry of
tick(), eeprom_word is 0xBEEF; avr-nm gives the addresses of tick, ticks and
bad_opcode_here; avr-objdump gives the stores and loads of ticks.

Run by ctest, one test per case:
  test_gdb.py --cli build/avrbench --firmware build/firmware GdbTests.test_x
Each avrbench and avr-gdb process runs under a wall-clock guard (a stuck
session fails the test instead of hanging it).
"""
import argparse
import os
import re
import subprocess
import sys
import time
import unittest

CLI = None
FIRMWARE = None
BOARDS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fixtures", "boards")
GUARD_S = 120  # wall-clock guard per process: generous, never a speed check


def elf(name):
    return os.path.join(FIRMWARE, name + ".elf")


def symbol_address(elf_path, name):
    out = subprocess.run(["avr-nm", elf_path], capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 3 and parts[2] == name:
            return int(parts[0], 16)
    raise AssertionError(f"{name} not in {elf_path}")


def disassembly_of(elf_path, function):
    """(address, mnemonic, operands) of each instruction of `function`."""
    out = subprocess.run(["avr-objdump", "-d", elf_path], capture_output=True, text=True, check=True).stdout
    rows, inside = [], False
    for line in out.splitlines():
        if re.match(r"^[0-9a-f]+ <" + re.escape(function) + r">:", line):
            inside = True
            continue
        if inside and re.match(r"^[0-9a-f]+ <", line):
            break
        m = re.match(r"^\s+([0-9a-f]+):\s+(?:[0-9a-f]{2} )+\s*(\w+)\s*([^;]*)", line)
        if inside and m:
            rows.append((int(m.group(1), 16), m.group(2), m.group(3).strip()))
    return rows


class Session:
    """avrbench run (or `command`) ... --gdb [MCU=]0 for each MCU; the ports it announces."""

    def __init__(self, run_args, mcus=("",), command=("run", "-q")):
        gdb_args = []
        for mcu in mcus:
            gdb_args += ["--gdb", (mcu + "=0") if mcu else "0"]
        self.proc = subprocess.Popen([CLI, *command] + run_args + gdb_args, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True)
        self.ports = {}
        deadline = time.monotonic() + GUARD_S
        while len(self.ports) < len(mcus):
            line = self.proc.stderr.readline()
            if not line or time.monotonic() > deadline:
                self.proc.kill()
                raise AssertionError("avrbench announced no gdb port: " + line + self.proc.stderr.read())
            m = re.search(r"gdb: MCU (\S+) waits for avr-gdb on 127\.0\.0\.1:(\d+)", line)
            if m:
                self.ports[m.group(1)] = int(m.group(2))

    def port(self, mcu="(first)"):
        return self.ports[mcu]

    def finish(self):
        out, err = self.proc.communicate(timeout=GUARD_S)
        return self.proc.returncode, out, err


def gdb_command(port, elf_path, commands):
    args = ["avr-gdb", "-nx", "-batch", "-ex", "set confirm off", "-ex", f"target remote :{port}"]
    for c in commands:
        args += ["-ex", c]
    return args + [elf_path]


def gdb(port, elf_path, commands):
    # One stream, in order: avr-gdb writes monitor output to stderr.
    r = subprocess.run(gdb_command(port, elf_path, commands), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True, timeout=GUARD_S)
    return r.stdout


def pcs(output):
    """Every `print $pc`: avr-gdb prints a code pointer as "(void (*)()) 0xa2 <tick+18>" (byte address)."""
    return [int(v, 16) for v in re.findall(r"^\$\d+ = \(void \(\*\)\(\)\) (0x[0-9a-f]+)", output, re.M)]


def values(output, name):
    """Every `$N = value` gdb printed, in order (`name` only for messages)."""
    found = re.findall(r"^\$\d+ = (.*)$", output, re.M)
    if not found:
        raise AssertionError(f"no value printed for {name}:\n{output}")
    return found


class GdbTests(unittest.TestCase):
    def test_break_on_a_symbol_reads_and_writes_variables_and_eeprom(self):
        target = elf("gdb_target")
        s = Session([target, "--for", "10ms"])
        out = gdb(s.port(), target, ["break tick"] + ["continue"] * 5 + [
            "print ticks", "print $pc", "x/2xb 0x810000",
            # A write by the debugger: the next entry sees it plus one increment.
            "set var ticks = 1000", "continue", "print ticks", "detach"])
        rc, _, err = s.finish()
        printed = values(out, "ticks, $pc")
        self.assertEqual(printed[0], "12", out)  # 5th entry: 3 * (5 - 1)
        self.assertEqual(pcs(out), [symbol_address(target, "tick")], out)
        self.assertRegex(out, r"<eeprom_word>:\s+0xef\s+0xbe", out)  # EEMEM 0xBEEF, little-endian
        self.assertEqual(printed[2], "1003", out)
        self.assertEqual(rc, 0, err)

    def test_watchpoints_stop_after_the_instruction_that_accessed_the_variable(self):
        target = elf("gdb_target")
        ticks = symbol_address(target, "ticks") & 0xFFFF
        stores = [a for a, op, args in disassembly_of(target, "tick")
                  if op == "sts" and args.split(",")[0].strip().lower() == f"0x{ticks:04x}"]
        loads = [a for a, op, args in disassembly_of(target, "main")
                 if op == "lds" and args.split(",")[1].strip().lower() == f"0x{ticks:04x}"]
        self.assertTrue(stores and loads)
        s = Session([target, "--for", "10ms"])
        out = gdb(s.port(), target, [
            "watch ticks", "continue", "print $pc", "delete",
            "rwatch ticks", "continue", "print $pc", "detach"])
        rc, _, err = s.finish()
        printed = pcs(out)
        # The write that changes ticks from 0 to 3 is the store of its low
        # byte (avr-gcc stores a volatile word high byte first): 4-byte STS.
        self.assertRegex(out, r"Old value = 0\s+New value = 3", out)
        self.assertEqual(printed[0], stores[-1] + 4, out)
        # The next read of ticks after that store is main's copy into
        # last_seen (the low byte's LDS comes first: 4 bytes too).
        self.assertEqual(printed[1], loads[0] + 4, out)
        self.assertEqual(rc, 0, err)

    def test_break_at_finding_stops_at_the_crashing_instruction(self):
        target = elf("crash_bad_opcode")
        s = Session([target, "--for", "10ms", "--break-at-finding"])
        out = gdb(s.port(), target, ["continue", "print $pc", "monitor findings", "kill"])
        rc, summary, err = s.finish()
        self.assertIn("SIGSEGV", out)
        self.assertEqual(pcs(out), [symbol_address(target, "bad_opcode_here")], out)
        stop = re.search(r"invalid-opcode at [0-9.]+ s \(cycle (\d+)\), PC 0x0086", out)
        reported = re.search(r"invalid-opcode at [0-9.]+ s \(cycle (\d+)\)", summary)
        self.assertTrue(stop and reported, out + summary)
        self.assertEqual(stop.group(1), reported.group(1))
        self.assertEqual(rc, 130, err)  # killed by the debugger: interrupted (docs/CLI.md)

    def test_a_finding_stepped_over_again_is_told_where_it_was_and_not_again(self):
        """step_boundaries on the CNC shield: its first STEP pulse is 15 cycles
        (step-high-too-short, A4988 needs 16), its second low time 15 cycles
        (step-low-too-short). Back 100 instructions from the first stop and
        forward 100 again, the first is told at the same instruction; the
        next continue goes on to the second (it stopped at the first again,
        one instruction later, before)."""
        target = elf("step_boundaries")
        s = Session([target, "--board", "arduino-uno-cnc-shield-v3", "--for", "10ms", "--break-at-finding"])
        out = gdb(s.port(), target, ["continue", "monitor time", "reverse-stepi 100", "monitor time", "stepi 100",
                                     "monitor time", "continue", "monitor time", "kill"])
        s.finish()
        told = re.findall(r"avrbench: stopped at a finding: x_driver: (step-\S+) at [0-9.]+ s \(cycle (\d+)\)", out)
        self.assertEqual([k for k, _ in told], ["step-high-too-short", "step-high-too-short", "step-low-too-short"], out)
        self.assertEqual(told[0][1], told[1][1], out)
        times = [int(n) for n in re.findall(r"MCU \S+: cycle \d+, [0-9.]+ s, (\d+) instructions", out)]
        self.assertEqual(len(times), 4, out)
        self.assertEqual(times[1], times[0] - 100, out)
        self.assertEqual(times[2], times[0], out)
        self.assertGreater(times[3], times[2] + 1, out)

    def test_inside_an_isr_the_interrupted_code_is_found_as_documented(self):
        """docs/DEBUGGING.md, "A backtrace inside an interrupt handler": avr-gdb's
        bt stops at the handler (its prologue analysis reads past RAMEND, which
        the server refuses), and the return address is at $sp+5, high byte
        first, under the 4 bytes blink_timer1's handler saved (r1, r0, SREG,
        r24: its prologue in avr-objdump) - ATmega328P section 7.7. It is
        main's idle loop, the `rjmp .-2` the compare match interrupts."""
        target = elf("blink_timer1")
        prologue = [m for _, m, _ in disassembly_of(target, "__vector_11")][:6]
        self.assertEqual(prologue, ["push", "push", "in", "push", "eor", "push"])
        idle_loop = [a for a, m, o in disassembly_of(target, "main") if m == "rjmp" and o.startswith(".-2")]
        self.assertEqual(len(idle_loop), 1)
        s = Session([target, "--for", "10ms"])
        out = gdb(s.port(), target, ["break __vector_11", "continue", "bt", "x/2xb $sp+5", "kill"])
        s.finish()
        self.assertIn("#0  __vector_11 ()", out)
        self.assertRegex(out, r"Backtrace stopped: Cannot access memory at address 0x8009[0-9a-f]{2}")
        m = re.search(r"^0x8008[0-9a-f]{2}:\s+0x([0-9a-f]{2})\s+0x([0-9a-f]{2})$", out, re.M)
        self.assertTrue(m, out)
        return_word = int(m.group(1), 16) << 8 | int(m.group(2), 16)
        self.assertEqual(return_word * 2, idle_loop[0], out)

    def test_reverse_stepi_100_then_stepi_100_returns_to_the_identical_state(self):
        target = elf("gdb_target")
        s = Session([target, "--for", "10ms"])
        state = ["info registers", "x/16xb 0x800100", "monitor time"]
        # Past the 5th entry of tick() (about 150 instructions from power-on: more than 100 to go back).
        out = gdb(s.port(), target, ["break tick"] + ["continue"] * 5 + ["delete", "stepi 37"] + state +
                  ["reverse-stepi 100", "monitor time", "stepi 100"] + state + ["detach"])
        rc, _, err = s.finish()
        times = re.findall(r"MCU \S+: cycle (\d+), [0-9.]+ s, (\d+) instructions", out)
        self.assertEqual(len(times), 3, out)
        before, back, again = [(int(c), int(n)) for c, n in times]
        self.assertEqual(back[1], before[1] - 100, out)
        self.assertEqual(again, before, out)
        blocks = re.split(r"MCU \S+: cycle", out)
        regs_before = re.findall(r"^(?:r\d+|SREG|SP|PC2|pc)\s.*$", blocks[0], re.M)
        regs_after = re.findall(r"^(?:r\d+|SREG|SP|PC2|pc)\s.*$", blocks[2], re.M)
        ram_before = re.findall(r"^0x8001[0-9a-f]{2}.*$", blocks[0], re.M)
        ram_after = re.findall(r"^0x8001[0-9a-f]{2}.*$", blocks[2], re.M)
        self.assertEqual(len(regs_before), 36, out)
        self.assertEqual(regs_before, regs_after)
        self.assertTrue(ram_before)
        self.assertEqual(ram_before, ram_after)
        self.assertEqual(rc, 0, err)

    def test_reverse_steps_deep_in_a_run_keep_the_debuggers_writes(self):
        """Half a second in (millions of instructions: replays start from a
        checkpoint), a write by the debugger, 30 steps on, 30 back and 30 on
        again: the write is made again where it was, and the state after the
        second 30 steps is the state after the first."""
        target = elf("gdb_target")
        s = Session([target, "--for", "1s", "--break-at", "500ms"])
        state = ["print ticks", "info registers", "monitor time"]
        out = gdb(s.port(), target, ["continue", "set var ticks = 1000", "print ticks"] + ["stepi 30"] + state +
                  ["reverse-stepi 30", "print ticks", "monitor time", "stepi 30"] + state + ["detach"])
        rc, _, err = s.finish()
        times = re.findall(r"MCU \S+: cycle (\d+), [0-9.]+ s, (\d+) instructions", out)
        self.assertEqual(len(times), 3, out)
        (c1, n1), (c2, n2), (c3, n3) = [(int(c), int(n)) for c, n in times]
        self.assertGreater(n1, 1000000, out)  # deep: half a second of a busy loop
        self.assertEqual(n2, n1 - 30)
        self.assertEqual((c3, n3), (c1, n1))
        printed = values(out, "ticks")
        # 1000 written; tick() adds 3 once per ~15-instruction pass: 30 steps cross at least one.
        self.assertEqual(printed[0], "1000")
        self.assertEqual(printed[2], "1000", out)  # back at the write: the write was made again
        self.assertEqual(printed[1], printed[3])
        self.assertNotEqual(printed[1], "1000")
        blocks = re.split(r"MCU \S+: cycle", out)
        regs = lambda block: re.findall(r"^(?:r\d+|SREG|SP|PC2|pc)\s.*$", block, re.M)
        self.assertEqual(len(regs(blocks[0])), 36, out)
        self.assertEqual(regs(blocks[0]), regs(blocks[2]))
        self.assertEqual(rc, 0, err)

    def test_reverse_continue_deep_in_a_run_to_breakpoints_and_a_watchpoint(self):
        """Half a second in: back to tick()'s entry twice (3 less each time,
        from the source), then back to the last write of last_seen, stopping
        in front of it (the value before it, as gdb's own record does) at the
        STS of its low byte (avr-objdump)."""
        target = elf("gdb_target")
        last_seen = symbol_address(target, "last_seen") & 0xFFFF
        stores = [a for a, op, args in disassembly_of(target, "main")
                  if op == "sts" and args.split(",")[0].strip().lower() == f"0x{last_seen:04x}"]
        self.assertEqual(len(stores), 1)
        s = Session([target, "--for", "1s", "--break-at", "500ms"])
        out = gdb(s.port(), target, ["continue", "finish", "print ticks", "break tick", "reverse-continue", "print ticks",
                                     "reverse-continue", "print ticks", "delete", "watch last_seen", "reverse-continue",
                                     "print last_seen", "print $pc", "detach"])
        rc, _, err = s.finish()
        printed = [int(v) for v in re.findall(r"^\$\d+ = (\d+)$", out, re.M)]
        self.assertEqual(len(printed), 4, out)
        t = printed[0]
        self.assertGreater(t, 10000, out)  # half a second of passes
        self.assertEqual(printed[1:], [t - 3, t - 6, t - 9], out)
        self.assertEqual(pcs(out), stores, out)
        self.assertEqual(rc, 0, err)

    def test_reverse_continue_goes_back_to_the_previous_breakpoint_hit(self):
        target = elf("gdb_target")
        s = Session([target, "--for", "10ms"])
        out = gdb(s.port(), target, ["break tick", "continue", "continue", "continue", "continue", "print ticks",
                                     "reverse-continue", "print ticks", "reverse-continue", "print ticks", "detach"])
        rc, _, err = s.finish()
        self.assertEqual(values(out, "ticks"), ["9", "6", "3"], out)  # entries 4, 3, 2
        self.assertEqual(rc, 0, err)

    def test_two_mcus_of_a_board_debugged_on_two_ports(self):
        target = elf("gdb_target")
        board = os.path.join(BOARDS, "two-mcus.yaml")
        s = Session(["--board", board, target, "--firmware", "right=" + target, "--for", "10ms"], mcus=("left", "right"))
        left = subprocess.Popen(gdb_command(s.port("left"), target, ["break tick"] + ["continue"] * 3 +
                                            ["print ticks", "monitor time", "detach"]),
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        right = subprocess.Popen(gdb_command(s.port("right"), target, ["break tick"] + ["continue"] * 7 +
                                             ["print ticks", "monitor time", "detach"]),
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        out_left = left.communicate(timeout=GUARD_S)[0]
        out_right = right.communicate(timeout=GUARD_S)[0]
        rc, summary, err = s.finish()
        self.assertEqual(values(out_left, "ticks"), ["6"], out_left)    # 3rd entry
        self.assertEqual(values(out_right, "ticks"), ["18"], out_right)  # 7th entry
        self.assertIn("MCU left:", out_left)
        self.assertIn("MCU right:", out_right)
        self.assertEqual(rc, 0, err + summary)

    def test_check_stops_where_a_scenario_leaves_its_golden(self):
        """blink_timer1's scenario against its golden with PB5's first rise
        moved 10 cycles later: check --gdb --break-at-divergence stops in
        front of the instruction that makes that edge: the ISR's write of PINB
        (I/O 0x03), found with avr-objdump."""
        import tempfile
        root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
        target = elf("blink_timer1")
        toggle = [a for a, op, args in disassembly_of(target, "__vector_11") if op == "out" and args.startswith("0x03,")]
        self.assertEqual(len(toggle), 1)
        with tempfile.TemporaryDirectory() as folder:
            with open(os.path.join(root, "tests", "scenarios", "blink_timer1.yaml")) as f:
                scenario = f.read()
            scenario = scenario.replace("board: ../../bench/boards/arduino-uno.yaml",
                                        "board: " + os.path.join(root, "bench", "boards", "arduino-uno.yaml"))
            scenario = scenario.replace("golden: ../../golden/blink_timer1.timeline", "golden: moved.timeline")
            with open(os.path.join(root, "golden", "blink_timer1.timeline")) as f:
                golden = f.read()
            self.assertIn("\n+16051 1\n", golden)
            with open(os.path.join(folder, "blink.yaml"), "w") as f:
                f.write(scenario)
            with open(os.path.join(folder, "moved.timeline"), "w") as f:
                f.write(golden.replace("\n+16051 1\n", "\n+16061 1\n", 1))
            s = Session([os.path.join(folder, "blink.yaml"), "--firmware-dir", FIRMWARE, "--break-at-divergence"],
                        command=("check",))
            out = gdb(s.port(), target, ["continue", "print $pc", "monitor time", "detach"])
            rc, summary, err = s.finish()
        self.assertEqual(pcs(out), toggle, out)
        self.assertIn("cycle 16051,", out)  # the golden's edge was at 16051 before it was moved
        self.assertEqual(rc, 1, summary + err)  # the scenario still fails its golden

    def test_a_fuzz_reproducer_opens_in_the_debugger_at_its_finding(self):
        """The delta listing's build accepts G1 Z-500, which no arm reaches
        (docs/DELTA.md): `fuzz --replay` of those lines under --gdb
        --break-at-finding stops at the finding, says it, and the run then
        ends with exit code 1 (a finding, as a replay counts them)."""
        import tempfile
        target = elf("delta_thesis")
        board = os.path.join(BOARDS, "..", "..", "..", "bench", "boards", "delta-seed004.yaml")
        with tempfile.TemporaryDirectory() as folder:
            reproducer = os.path.join(folder, "finding-1.gcode")
            with open(reproducer, "w") as f:
                f.write("G1 X100 Y-67 Z-340\nG1 Z-500\n")
            s = Session(["--elf", target, "--board", board, "--replay", reproducer, "--break-at-finding"],
                        command=("fuzz",))
            out = gdb(s.port(), target, ["continue", "monitor findings", "continue"])
            rc, summary, err = s.finish()
        # Two findings name the line at its answer: the robot's reach check
        # and the motion oracle (the arms never go there); it stops at one
        # and `monitor findings` lists the reach check's.
        self.assertIn("avrbench: stopped at a finding: ", out)
        self.assertIn("robot: target-out-of-reach", out)
        self.assertIn("line 2 'G1 Z-500' was answered ok", out)
        self.assertIn("exited", out)  # the second continue runs to the end: W00
        self.assertEqual(rc, 1, summary + err)

    def test_malformed_packets_get_answers_and_the_run_goes_on(self):
        """A client that is not avr-gdb: every packet gets a reply (an error
        or the empty "unsupported" one), nothing ends the run, and after a
        detach it finishes with exit code 0."""
        import random
        import socket
        target = elf("gdb_target")
        s = Session([target, "--for", "1ms"])
        conn = socket.create_connection(("127.0.0.1", s.port()), timeout=GUARD_S)
        stream = conn.makefile("rwb", buffering=0)

        def receive(payload):
            reply = b""
            while not reply.endswith(b"#"):  # '+' acknowledgements, then $...#
                c = stream.read(1)
                self.assertTrue(c, "connection closed after " + repr(payload))
                if reply or c == b"$":
                    reply += c
            stream.read(2)  # checksum
            stream.write(b"+")
            return reply[1:-1]

        def exchange(payload):
            stream.write(b"$" + payload + b"#" + b"%02x" % (sum(payload) & 0xFF))
            reply = receive(payload)
            while reply.startswith(b"O") and reply != b"OK":  # console output comes before the answer
                reply = receive(payload)
            return reply

        rng = random.Random(39)  # seeded: the same packets every run
        packets = [b"", b"m", b"m,", b"mffffffff,ffffffff", b"M0,4:zz", b"X800100,3:ab", b"P", b"P1", b"Pff=00",
                   b"p", b"pff", b"G", b"G00", b"Z", b"Z2", b"Z2,800100", b"z9,0,0", b"qRcmd,", b"qRcmd,zz",
                   b"qRcmd," + b"help".hex().encode(), b"vCont;q", b"qXfer:features:read:target.xml:0,fff", b"!", b"\xff" * 3]
        for _ in range(200):
            packets.append(bytes(rng.choice(b"mMXpPgGZzqv0123456789abcdef,:=;#$}*") for _ in range(rng.randint(1, 24))))
        for packet in packets:
            packet = bytes(c for c in packet if c not in b"#$}*")  # framing characters go escaped on the wire
            if packet[:1] in (b"c", b"s", b"b", b"k", b"D") or packet.startswith(b"vKill"):
                continue  # run control: it would run, step, replay or end the program, not malformed
            exchange(packet)
        # The server still reads memory right: tick()'s first 4 flash bytes
        # as binutils gives them (avr-objcopy of .text, at avr-nm's address).
        import tempfile
        tick = symbol_address(target, "tick")
        with tempfile.TemporaryDirectory() as tmp:
            text = os.path.join(tmp, "text.bin")
            subprocess.run(["avr-objcopy", "-O", "binary", "-j", ".text", target, text], check=True)
            with open(text, "rb") as f:
                expected = f.read()[tick:tick + 4].hex().encode()
        self.assertNotEqual(expected, b"00000000")
        self.assertEqual(exchange(b"m%x,4" % tick), expected)
        self.assertEqual(exchange(b"D"), b"OK")
        conn.close()
        rc, _, err = s.finish()
        self.assertEqual(rc, 0, err)

    def test_gdb_sees_the_runs_exit_code(self):
        # blink_timer1 never answers a G-code line: the job is unfinished when
        # --for ends, a timeout (exit 3, README "Exit codes"), which gdb hears
        # in the RSP 'W' packet and prints as the inferior's exit code.
        target = elf("blink_timer1")
        job = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"gdb-exit-{os.getpid()}.gcode")
        with open(job, "w") as f:
            f.write("G1 X1\n")
        s = Session([target, "--board", "arduino-uno", "--gcode", job, "--for", "0.5s"])
        out = gdb(s.port(), target, ["continue"])
        rc, _, err = s.finish()
        os.remove(job)
        self.assertEqual(rc, 3, err)
        self.assertIn("exited with code 03]", out)

    def test_bad_gdb_option_is_one_line_with_the_bad_input_exit_code(self):
        r = subprocess.run([CLI, "run", elf("gdb_target"), "--gdb", "x=notaport"], capture_output=True, text=True,
                           timeout=GUARD_S)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn("--gdb 'x=notaport'", r.stderr)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--cli", required=True)
    parser.add_argument("--firmware", required=True)
    args, rest = parser.parse_known_args()
    CLI, FIRMWARE = os.path.abspath(args.cli), os.path.abspath(args.firmware)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
