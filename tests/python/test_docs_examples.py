# docs/PYTHON.md's examples run as written: each indented code block that
# uses avrbench, taken from the file itself, in a scratch folder holding the
# files it names (grbl_stepper.elf; build/firmware/... for the ones that name
# the build's path).
import pathlib
import re
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def examples():
    text = (ROOT / "docs" / "PYTHON.md").read_text()
    blocks, current = [], []
    for line in text.splitlines() + [""]:
        if line.startswith("    ") or (current and line == ""):
            current.append(line[4:])
            continue
        if current:
            blocks.append("\n".join(current).strip() + "\n")
        current = []
    return [b for b in blocks if "avrbench" in b and ("Bench(" in b or "mark.avrbench" in b)]


def scratch_with_firmware(tmp_path, elf):
    (tmp_path / "build" / "firmware").mkdir(parents=True)
    for name in ("grbl_stepper", "thermal_pid"):
        shutil.copy(elf(name), tmp_path / "build" / "firmware" / (name + ".elf"))
    shutil.copy(elf("grbl_stepper"), tmp_path / "grbl_stepper.elf")
    return tmp_path


def test_the_doc_has_its_three_examples():
    found = examples()
    assert len(found) == 3, found
    assert "pytest.approx(106.4)" in found[0] and "mark.avrbench" in found[1] and "np.diff" in found[2]


def test_the_api_example(elf, tmp_path):
    work = scratch_with_firmware(tmp_path, elf)
    r = subprocess.run([sys.executable, "-c", examples()[0]], cwd=work, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    # "leaving the block writes job.vcd, job.gtkw and job.html"
    assert all((work / f).exists() for f in ("job.vcd", "job.gtkw", "job.html"))


def test_the_plugin_example(elf, tmp_path):
    work = scratch_with_firmware(tmp_path, elf)
    (work / "test_hot_end.py").write_text(examples()[1])
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_hot_end.py"], cwd=work,
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "1 passed" in r.stdout


def test_the_notebook_example(elf, tmp_path):
    work = scratch_with_firmware(tmp_path, elf)
    r = subprocess.run([sys.executable, "-c", examples()[2]], cwd=work, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    # X4000: a move of 4000 steps (firmware/boards/grbl_stepper/README.md: "X1600 ... (steps)").
    assert re.match(r"^4000 steps, at most \d+ steps/s$", r.stdout.strip()), r.stdout
