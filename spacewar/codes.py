"""Action codes: the compact integers the compiled game takes (no numba here, so that a bot's
process can import the protocol without loading the compiled game).

code = turn index (0, 1, 2 for turn -1, 0, +1) + 3 thrust + 6 fire + 12 hyperspace + 24 flip.
"""
import numpy as np

N_ACTIONS = 48
NOOP = 1
#: what each MultiDiscrete part (turn index, thrust, fire, hyperspace, flip) weighs in a code
PART_WEIGHTS = (1, 3, 6, 12, 24)


def codes_from_parts(parts):
    """(K, 4) or (K, 5) MultiDiscrete actions (turn index, thrust, fire, hyperspace[, flip])
    as the game's action codes (K,) int64."""
    parts = np.asarray(parts, dtype=np.int64)
    width = parts.shape[-1] if parts.ndim else 0
    if width not in (4, 5):
        raise ValueError(f"MultiDiscrete actions have 4 or 5 parts, got shape {parts.shape}")
    return parts.reshape(-1, width) @ np.array(PART_WEIGHTS[:width], dtype=np.int64)
