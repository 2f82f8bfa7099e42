"""The game's compiled code lives in its own cache directory, whatever module is imported first."""
import subprocess
import sys

import pytest


@pytest.mark.parametrize("first", ["spacewar.arena.match", "spacewar.replay", "spacewar.game.core",
                                   "spacewar.game"])
def test_the_game_caches_its_compiled_code_in_its_directory(first):
    # numba fixes a function's cache location when it is decorated: importing the frame's
    # module before spacewar.game must not put its machine code beside the source, keyed on
    # core.py alone (an engine edit would then leave the game running stale engine kernels)
    code = (f"import {first}\n"
            "from spacewar.game import core\n"
            "from engine.cache import cache_dir\n"
            "print(core.step_all._cache._cache_path)\n"
            "print(cache_dir('spacewar'))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600, check=True).stdout.split("\n")
    assert out[0].startswith(out[1]), out
