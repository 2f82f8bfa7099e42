"""The keys of the Spacewar! window: who flies with which keys, and what controls a viewer.

Plain tables and pure functions (no pygame, no numpy), so that ``spacewar --help`` can list the
keys without loading the game. Keys are named as pygame names its ``K_`` constants, lower
case: ``"a"``, ``"left"``, ``"space"``, ``"rctrl"``, ``"kp4"``, ``"["``.

Flying (``spacewar play``). One person at the keyboard, in either seat, gets ``SOLO``: both
hands' keys at once, as the game has always had. Two people share the keyboard as the 1962
players shared the PDP-1's two control boxes: ``PLAYER_1`` on the left hand's WASD keys,
``PLAYER_2`` on the arrows with the right-hand modifiers (or the numeric keypad). Pressing
both turn keys at once is hyperspace in every set, as on the original control boxes.

Viewing (``spacewar watch``, ``spacewar replay --view``): ``WATCH_KEYS`` and ``REPLAY_KEYS``,
close to what video players use (Space pauses, ``,`` and ``.`` step one frame, ``[`` and ``]``
change the speed).
"""
from bisect import bisect_right
from dataclasses import dataclass

#: pygame's constant for each key name used anywhere (``getattr(pygame, KEY_CONSTANTS[name])``)
KEY_CONSTANTS = {
    **{c: "K_" + c for c in "abcdefghijklmnopqrstuvwxyz0123456789"},
    "space": "K_SPACE", "escape": "K_ESCAPE", "return": "K_RETURN", "backspace": "K_BACKSPACE",
    "left": "K_LEFT", "right": "K_RIGHT", "up": "K_UP", "down": "K_DOWN",
    "home": "K_HOME", "end": "K_END", "pageup": "K_PAGEUP", "pagedown": "K_PAGEDOWN",
    "rctrl": "K_RCTRL", "rshift": "K_RSHIFT", "lctrl": "K_LCTRL", "lshift": "K_LSHIFT",
    "[": "K_LEFTBRACKET", "]": "K_RIGHTBRACKET", ",": "K_COMMA", ".": "K_PERIOD",
    "-": "K_MINUS", "=": "K_EQUALS",
    **{f"kp{d}": f"K_KP{d}" for d in range(10)},
    "kp_enter": "K_KP_ENTER", "kp_plus": "K_KP_PLUS", "kp_minus": "K_KP_MINUS",
}


@dataclass(frozen=True)
class KeySet:
    """The keys one pilot flies with; each field a frozenset of key names."""

    name: str
    left: frozenset
    right: frozenset
    thrust: frozenset
    fire: frozenset
    hyperspace: frozenset
    flip: frozenset

    @property
    def names(self):
        return self.left | self.right | self.thrust | self.fire | self.hyperspace | self.flip

    def action(self, held):
        """``(turn, thrust, fire, hyperspace, flip)`` for the set of held key names; both turn
        keys at once is hyperspace (the 1962 control boxes had no separate button)."""
        left = bool(held & self.left)
        right = bool(held & self.right)
        turn = 0 if left == right else (1 if left else -1)  # +1 anticlockwise, screen y is up
        return (turn, bool(held & self.thrust), bool(held & self.fire),
                bool(held & self.hyperspace) or (left and right), bool(held & self.flip))

    def help(self, short=False):
        """``(keys, what they do)`` rows for ``--help``, or (``short``) for the screen."""
        return (
            (_turn_keys(self.left, self.right), "turn"),
            (_shown(self.thrust), "thrust"),
            (_shown(self.fire), "fire"),
            (_shown(self.hyperspace) + ("" if short else " or both turn keys"), "hyperspace"),
            (_shown(self.flip), "flip" if short else "flip polarity (electric mode)"),
        )


_SHOWN = {"space": "Space", "escape": "Esc", "return": "Enter", "backspace": "Backspace",
          "left": "Left", "right": "Right", "up": "Up", "down": "Down", "home": "Home",
          "end": "End", "pageup": "PgUp", "pagedown": "PgDn", "rctrl": "RCtrl",
          "rshift": "RShift", "lctrl": "LCtrl", "lshift": "LShift", "kp_enter": "KpEnter",
          "kp_plus": "Kp+", "kp_minus": "Kp-"}


def _turn_keys(left, right):
    """``"A/D or Left/Right"``: each left-turn key beside its right-turn partner."""
    lefts, rights = _ordered(left), _ordered(right)
    if len(lefts) != len(rights):
        return f"{_shown(left)} / {_shown(right)}"
    return " or ".join(f"{_label(a)}/{_label(b)}" for a, b in zip(lefts, rights))


def _ordered(names):
    """Letters first, then named keys, then the keypad's."""
    return sorted(names, key=lambda n: (len(n) > 1, n.startswith("kp"), n))


def _label(name):
    if name in _SHOWN:
        return _SHOWN[name]
    if name.startswith("kp") and name[2:].isdigit():
        return "Kp" + name[2:]
    return name.upper()


def _shown(names):
    """Key names as a person reads them (``"S or Space"``), in a fixed order."""
    return " or ".join(_label(n) for n in _ordered(names))


def _keys(*names):
    return frozenset(names)


#: one person at the keyboard: both hands' keys (the game's keys since it had a window)
SOLO = KeySet("solo", left=_keys("a", "left"), right=_keys("d", "right"), thrust=_keys("w", "up"),
              fire=_keys("space", "s"), hyperspace=_keys("h"), flip=_keys("f"))
#: two people: the first on the left hand's WASD keys
PLAYER_1 = KeySet("player 1", left=_keys("a"), right=_keys("d"), thrust=_keys("w"),
                  fire=_keys("s", "space"), hyperspace=_keys("e"), flip=_keys("f"))
#: two people: the second on the arrows and the right-hand keys, or the numeric keypad
PLAYER_2 = KeySet("player 2", left=_keys("left", "kp4"), right=_keys("right", "kp6"),
                  thrust=_keys("up", "kp8"), fire=_keys("down", "rctrl", "kp5"),
                  hyperspace=_keys("rshift", "kp0"), flip=_keys("return", "kp_enter"))

# -- playing ------------------------------------------------------------------------------
PLAY_PAUSE = _keys("p")
PLAY_QUIT = _keys("escape")
#: every key ``spacewar play`` reads
PLAY_KEY_NAMES = SOLO.names | PLAYER_1.names | PLAYER_2.names | PLAY_PAUSE | PLAY_QUIT

# -- viewing ------------------------------------------------------------------------------
PAUSE = _keys("space", "p")
STEP_FORWARD = _keys(".")
STEP_BACK = _keys(",")
FASTER = _keys("]", "up", "=", "kp_plus")
SLOWER = _keys("[", "down", "-", "kp_minus")
NORMAL_SPEED = _keys("1")
REWIND = _keys("backspace", "r")  # held
JUMP_BACK = _keys("left", "pageup")
JUMP_FORWARD = _keys("right", "pagedown")
TO_START = _keys("home")
TO_END = _keys("end")
QUIT = _keys("escape", "q")
JUMP_SECONDS = 5  # of game time: fps frames a second at 1x

WATCH_KEY_NAMES = PAUSE | STEP_FORWARD | FASTER | SLOWER | NORMAL_SPEED | QUIT
REPLAY_KEY_NAMES = (WATCH_KEY_NAMES | STEP_BACK | REWIND | JUMP_BACK | JUMP_FORWARD | TO_START
                    | TO_END)

#: the speeds a viewer steps through (game time per wall time), slowest first
SPEEDS = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0)


def speed_label(speed):
    """``"1/8x"``, ``"1x"``, ``"8x"``."""
    if speed >= 1:
        return f"{speed:g}x"
    return f"1/{1 / speed:g}x"


PLAY_CONTROLS_HELP = (("P", "pause / resume"), ("Esc", "quit"))
_SPEED_RANGE = f"{speed_label(SPEEDS[0])} to {speed_label(SPEEDS[-1])}"
WATCH_KEYS_HELP = (
    ("Space or P", "pause / resume"),
    (". (paused)", "one frame forward"),
    ("] or Up / [ or Down", f"faster / slower ({_SPEED_RANGE})"),
    ("1", "normal speed"),
    ("Esc or Q", "quit"),
)
REPLAY_KEYS_HELP = (
    ("Space or P", "pause / resume"),
    (". / ,", "one frame forward / back (pauses)"),
    ("hold R or Backspace", "rewind (backwards at the current speed)"),
    ("Right or PgDn / Left or PgUp", f"jump {JUMP_SECONDS} s forward / back"),
    ("Home / End", "to the start / the end"),
    ("click the bar", "jump to that point"),
    ("] or Up / [ or Down", f"faster / slower ({_SPEED_RANGE})"),
    ("1", "normal speed"),
    ("Esc or Q", "quit"),
)


def help_text(title, rows):
    """A block of ``keys   what`` lines under ``title``, for an argparse epilog."""
    width = max(len(keys) for keys, _ in rows)
    return "\n".join([title] + [f"  {keys:<{width}}  {what}" for keys, what in rows])


def play_epilog():
    return "\n\n".join([
        help_text("Keys, one person (either seat):", SOLO.help()),
        help_text("Keys, two people (--p1 human --p2 human), player 1:", PLAYER_1.help()),
        help_text("player 2 (or the numeric keypad):", PLAYER_2.help()),
        help_text("Both:", PLAY_CONTROLS_HELP),
    ])


def watch_epilog():
    return help_text("Keys while watching:", WATCH_KEYS_HELP)


def replay_epilog():
    return help_text("Keys of the replay window (--view):", REPLAY_KEYS_HELP)


# -- scripted keys ------------------------------------------------------------------------
def key_set(keys, where, known):
    """``keys`` (a key name or an iterable of them) as a frozenset of lower-case names, each
    one of ``known``; else ValueError naming ``where`` and the unknown names."""
    if isinstance(keys, str):
        keys = {keys}
    try:
        names = frozenset(str(k).lower() for k in keys)
    except TypeError:
        raise ValueError(f"{where}: keys must be a set of key names, got {keys!r}") from None
    unknown = sorted(names - known)
    if unknown:
        raise ValueError(f"{where}: unknown key name(s) {', '.join(map(repr, unknown))}; "
                         f"known: {', '.join(sorted(known))}")
    return names


def script_source(script, known=PLAY_KEY_NAMES):
    """A function ``tick -> frozenset of held key names`` from a script of keys.

    ``script`` is either a callable ``tick -> keys`` or a sequence of ``(tick, keys)``: from
    each listed tick on, exactly those keys are held (until the next entry). Ticks count the
    window's fixed-rate ticks (``fps`` a second) from the start, paused or not, whatever the
    speed (so a script can pause, resume and change speed); a key appearing in a tick's set
    that was not held the tick before is a press. ``known``: the key names allowed.
    """
    if callable(script):
        return lambda tick: key_set(script(tick), f"script({tick})", known)
    try:
        entries = sorted((int(t), key_set(keys, f"script entry at tick {t}", known))
                         for t, keys in script)
    except (TypeError, ValueError) as exc:
        if isinstance(exc, ValueError) and "key" in str(exc):
            raise
        raise ValueError("script must be a callable or a sequence of (tick, set of key names), "
                         f"got {script!r}") from None
    ticks = [t for t, _ in entries]
    empty = frozenset()

    def held(tick):
        i = bisect_right(ticks, tick) - 1
        return entries[i][1] if i >= 0 else empty

    return held


__all__ = ["KeySet", "SOLO", "PLAYER_1", "PLAYER_2", "KEY_CONSTANTS", "PLAY_KEY_NAMES",
           "WATCH_KEY_NAMES", "REPLAY_KEY_NAMES", "SPEEDS", "speed_label", "script_source",
           "key_set", "help_text", "play_epilog", "watch_epilog", "replay_epilog"]
