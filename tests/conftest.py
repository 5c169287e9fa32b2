from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def mixed_urdf() -> str:
    """A chain with revolute, continuous, prismatic and fixed joints (tests/data/mixed_chain.urdf)."""
    return str(DATA / "mixed_chain.urdf")
