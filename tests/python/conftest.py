# The module's own tests: $AVRBENCH_CLI and $AVRBENCH_FIRMWARE come from
# ctest (tests/CMakeLists.txt) or ci/test; defaults for a run from the
# checkout after `bash ci/build`.
import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CLI = os.environ.get("AVRBENCH_CLI", str(ROOT / "build" / "avrbench"))
FIRMWARE = pathlib.Path(os.environ.get("AVRBENCH_FIRMWARE", ROOT / "build" / "firmware"))


@pytest.fixture
def elf():
    return lambda name: str(FIRMWARE / (name + ".elf"))


@pytest.fixture
def cli():
    return CLI


@pytest.fixture
def root():
    return ROOT
