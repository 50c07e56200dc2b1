import pytest

import trum


@pytest.fixture(scope="session")
def motor() -> trum.Motor:
    return trum.Motor("trum60a")
