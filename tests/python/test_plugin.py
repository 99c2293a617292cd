"""The pytest plugin (entry point pytest11 "avrbench") in a pytest of its
own: the bench fixture from a marker and from the command-line options, a
failing test's waveforms and report kept and named, a passing test's not,
JUnit properties, and pytest-xdist running the tests in parallel."""
import pathlib
import subprocess
import sys
import xml.etree.ElementTree as ElementTree

TESTS = '''
import pytest

@pytest.mark.avrbench(board="arduino-uno", firmware="{elf}")
def test_passes(bench):
    bench.run_for("2ms")
    assert bench.now > 0.001

@pytest.mark.avrbench(board="arduino-uno", firmware="{elf}")
def test_fails(bench):
    bench.run_for("2ms")
    assert bench.findings, "blink_timer1 has no findings: this test fails on purpose"

def test_from_the_command_line(bench):
    assert bench.mcus == ["uno"]
'''


def test_the_plugin_keeps_a_failing_tests_waveforms(elf, tmp_path):
    (tmp_path / "test_firmware.py").write_text(TESTS.format(elf=elf("blink_timer1")))
    junit = tmp_path / "junit.xml"
    r = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-n", "2",
                        "--basetemp", str(tmp_path / "runs"), "--junitxml", str(junit),
                        "--avrbench-board", "arduino-uno", "--avrbench-elf", elf("blink_timer1"),
                        str(tmp_path / "test_firmware.py")], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    out = r.stdout + r.stderr
    assert r.returncode == 1, out
    assert "1 failed, 2 passed" in out, out
    assert "gw0 [3] / gw1 [3]" in out, out  # two xdist workers ran them
    named = [pathlib.Path(p) for p in
             __import__("re").findall(r"waveforms: (\S+\.vcd)", out)]
    assert len(named) == 1 and named[0].exists(), out
    assert "test_fails" in str(named[0])
    assert (named[0].parent / "bench.html").exists() and (named[0].parent / "bench.gtkw").exists()
    assert list((tmp_path / "runs").rglob("*.vcd")) == named  # passing tests keep nothing
    properties = {p.get("name"): p.get("value") for p in ElementTree.parse(junit).iter("property")}
    assert properties.get("avrbench_vcd") == str(named[0])


def test_no_board_is_a_clear_error(tmp_path):
    (tmp_path / "test_nothing.py").write_text("def test_needs_a_board(bench):\n    pass\n")
    r = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", str(tmp_path / "test_nothing.py")],
                       capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert r.returncode == 1
    assert "bench fixture: no board" in r.stdout
