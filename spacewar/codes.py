"""Action codes: the compact integers the compiled game takes (no numba here, so that a bot's
process can import the protocol without loading the compiled game).

code = turn index (0, 1, 2 for turn -1, 0, +1) + 3 thrust + 6 fire + 12 hyperspace + 24 flip.
"""
N_ACTIONS = 48
NOOP = 1
