"""Fixtures of the whole test suite."""

import pytest

from bem import checks

#: the memory the node guard reads in every test [bytes]: that of 16 million nodes of a half-space
#: region, so that no test depends on the memory of the machine it runs on
TEST_MEMORY = 16_000_000 * checks.BYTES_PER_NODE["candidate region"]


@pytest.fixture(autouse=True)
def _machine_memory(monkeypatch):
    """Pin :func:`bem.checks.machine_memory` to :data:`TEST_MEMORY`."""
    monkeypatch.setattr(checks, "machine_memory", lambda: TEST_MEMORY)
