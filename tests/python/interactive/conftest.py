"""The interactive tests' sessions: small scenes, built anew for each test."""
import pytest
import tool_scripts


@pytest.fixture
def cut_session():
    return tool_scripts.cut_session()


@pytest.fixture
def needle_session():
    return tool_scripts.needle_session()
