"""The compiled-code cache is keyed per package on the sources it is built from: the engine's
key on the engine's sources only, the game's on the engine's and the game's."""
import shutil

import pytest

import engine.cache as cache

PACKAGES = ("engine", "spacewar", "validation")


@pytest.fixture
def real_keys():
    cache.source_hash.cache_clear()
    return {package: cache.source_hash(package) for package in PACKAGES}


@pytest.fixture
def tree(tmp_path, monkeypatch, real_keys):
    """A copy of the three packages' .py files, which ``source_hash`` reads instead."""
    for package in PACKAGES:
        for path in (cache._ROOT / package).rglob("*.py"):
            target = tmp_path / path.relative_to(cache._ROOT)
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, target)
    monkeypatch.setattr(cache, "_ROOT", tmp_path)
    cache.source_hash.cache_clear()
    yield tmp_path
    cache.source_hash.cache_clear()  # the real sources' hashes again for whoever asks next


def _keys():
    cache.source_hash.cache_clear()
    return {package: cache.source_hash(package) for package in PACKAGES}


def _edit(path):
    path.write_text(path.read_text() + "\n# an edit\n")


def test_the_copy_has_the_real_keys(tree, real_keys):
    assert _keys() == real_keys


@pytest.mark.parametrize("where", ["spacewar/rules.py", "validation/problems.py"])
def test_engine_key_ignores_the_game_and_the_validation(tree, where):
    before = _keys()
    _edit(tree / where)
    after = _keys()
    assert after["engine"] == before["engine"]
    edited = where.split("/")[0]
    assert after[edited] != before[edited]
    for package in PACKAGES:
        if package not in ("engine", edited):
            assert after[package] == before[package]


def test_engine_edit_changes_every_key(tree):
    before = _keys()
    _edit(tree / "engine" / "clock.py")
    after = _keys()
    for package in PACKAGES:
        assert after[package] != before[package], package


def test_new_engine_file_changes_the_engine_key(tree):
    before = _keys()
    (tree / "engine" / "forces" / "extra.py").write_text("X = 1\n")
    after = _keys()
    assert after["engine"] != before["engine"] and after["spacewar"] != before["spacewar"]


def test_cache_dir_is_per_package_and_key(tree, tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    keys = _keys()
    # the game's bots mirror numpy's dot, which rounds by machine: its name says which way
    kind = {"engine": "", "validation": "", "spacewar": cache.numpy_dot_kind()[0]}
    for package in PACKAGES:
        expected = tmp_path / "numba" / f"numba-{package}-{keys[package]}{kind[package]}"
        assert cache.cache_dir(package) == str(expected)
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_dir("spacewar") == str(
        tmp_path / "xdg" / "nbody-spacewar" / f"numba-spacewar-{keys['spacewar']}{kind['spacewar']}")
