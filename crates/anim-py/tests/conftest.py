import os

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
RIGID_DATA = os.path.join(ROOT, "crates", "anim-rigid", "testdata")


@pytest.fixture
def rigid_data():
    return RIGID_DATA
