"""Reading a replay's records and re-simulating its match: ``actions``, ``fault_record``,
``simulate``."""


from spacewar.game.game import Game
from spacewar.replay.format import ReplayError
from spacewar.replay.schema import checked_rules, decode_codes

def actions(replay):
    """The (frames, 2) array of action codes of a replay."""
    text = replay["actions"]
    if not isinstance(text, str):
        raise ReplayError(f"replay actions must be a base64 string, got {type(text).__name__}")
    return decode_codes("replay", "actions", text)


def fault_record(replay):
    """The (frames asked, 2) array of fault kind codes (0 = none), or None (version 1)."""
    text = replay.get("faults")
    if text is None:
        return None
    if not isinstance(text, str):
        raise ReplayError(f"replay faults must be a base64 string, got {type(text).__name__}")
    return decode_codes("replay", "faults", text)


def new_game(replay):
    rules = checked_rules("replay", "rules", replay["rules"])
    try:
        return Game(rules, seeds=[replay["seed"]], rounds=replay["rounds"])
    except (TypeError, ValueError, OverflowError) as exc:
        raise ReplayError(f"replay seed or rounds are invalid: {exc}") from None


def simulate(replay, on_frame=None):
    """Re-run a replay's frames; return the Game at the end.

    Raises ReplayError if actions are recorded after the match was over.
    """
    game = new_game(replay)
    if on_frame is not None:
        on_frame(game)
    for i, row in enumerate(actions(replay)):
        if game.over[0]:
            raise ReplayError(f"replay has actions recorded past the end of the match: frame "
                              f"{i} of {replay['frames']} comes after the game was over")
        game.step(row[None, :])
        if on_frame is not None:
            on_frame(game)
    return game
