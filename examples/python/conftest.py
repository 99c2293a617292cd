# Where the example tests find the firmware they run: $AVRBENCH_FIRMWARE
# (ci/test points it at build/firmware), else build/firmware beside this
# checkout. A firmware team's own conftest names its build output instead.
import os
import pathlib

import pytest

FIRMWARE = pathlib.Path(os.environ.get("AVRBENCH_FIRMWARE",
                                       pathlib.Path(__file__).resolve().parents[2] / "build" / "firmware"))


@pytest.fixture
def firmware():
    return lambda name: str(FIRMWARE / (name + ".elf"))
