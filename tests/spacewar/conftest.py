import pytest


@pytest.fixture(autouse=True)
def replay_key(tmp_path_factory, monkeypatch):
    """Replays are signed with a key of the test run's own, never the user's."""
    path = tmp_path_factory.getbasetemp() / "replay-key"
    monkeypatch.setenv("SPACEWAR_REPLAY_KEY_FILE", str(path))
    return path


@pytest.fixture(scope="module")
def gymnasium(optional):
    """Gymnasium (an optional package: tests/conftest.py ``optional``)."""
    return optional("gymnasium")


@pytest.fixture(scope="module")
def envs(gymnasium):
    """spacewar.learn.envs (importing it registers Spacewar-v0)."""
    import spacewar.learn.envs

    return spacewar.learn.envs
