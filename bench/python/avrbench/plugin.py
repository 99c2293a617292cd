"""The avrbench pytest plugin (entry point pytest11 "avrbench").

A `bench` fixture: the board and firmware come from the test's marker,
`@pytest.mark.avrbench(board="arduino-uno", firmware="fw.elf")`, else from
the command line, `--avrbench-board BOARD --avrbench-elf ELF`. A failing
test keeps its waveforms and report, `bench.vcd` (+ `bench.gtkw`) and
`bench.html` in the test's tmp_path, named in the failure output (an
"avrbench" section) and in the JUnit XML as properties; a passing test
writes nothing. Runs in parallel with pytest-xdist (`pytest -n 2`): each
test has its own Bench. docs/PYTHON.md.
"""
import pytest

import avrbench


def pytest_addoption(parser):
    group = parser.getgroup("avrbench", "avrbench: AVR firmware on an emulated board")
    group.addoption("--avrbench-board", default=None, help="board file or standard board name for the bench fixture")
    group.addoption("--avrbench-elf", default=None, help="firmware ELF for the board's first MCU")


def pytest_configure(config):
    config.addinivalue_line(
        "markers", "avrbench(board=None, firmware=None, profile=False): the bench fixture's board and firmware")


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    paths = getattr(item, "_avrbench_outputs", None)
    if paths is None or report.when != "call":
        return
    item._avrbench_failed = report.failed
    if report.failed:
        text = "waveforms: {0} (gtkwave {1})\nreport:    {2}".format(*paths)
        report.sections.append(("avrbench", text))
        item.user_properties.append(("avrbench_vcd", paths[0]))
        item.user_properties.append(("avrbench_report", paths[2]))


@pytest.fixture
def bench(request, tmp_path):
    marker = request.node.get_closest_marker("avrbench")
    options = dict(marker.kwargs) if marker else {}
    board = options.pop("board", None) or request.config.getoption("--avrbench-board")
    firmware = options.pop("firmware", None) or request.config.getoption("--avrbench-elf")
    if not board:
        raise avrbench.BadInput("bench fixture: no board (@pytest.mark.avrbench(board=...) or --avrbench-board)")
    vcd, gtkw, html = tmp_path / "bench.vcd", tmp_path / "bench.gtkw", tmp_path / "bench.html"
    request.node._avrbench_outputs = (str(vcd), str(gtkw), str(html))
    b = avrbench.Bench(board, firmware, vcd=vcd, report=html, **options)
    yield b
    b.close(write=getattr(request.node, "_avrbench_failed", True))
