"""Game: M Spacewar! matches held in arrays and advanced together by one compiled call.

    game = Game(Rules(), seeds=[1, 2, 3], rounds=5)
    while not game.over.all():
        game.step(actions)            # (M, 2) action codes or Action objects
    game.scores                       # (M, 2)

    saved = game.checkpoint(0)        # match 0's whole state, copied
    game.restore(saved, 0)            # back to it: stepping on gives bit-identical frames

The matches are one ``engine.Batch`` (a system per match, on the periodic space of side 1). The
force model of a mode is declared on it with the engine's own force terms (only the terms the
mode needs) and packed by the engine; the compiled frame then calls the engine's per-system
kernel (``engine.batch.advance_system``) on each match.
"""
import hashlib

import numpy as np

from engine import Batch, forces

from spacewar.game import core
from spacewar.game import features
from spacewar.protocol import Action, observation_from_raw, raw_length
from spacewar.rules import Rules, count_at_least


def force_terms(rules):
    """The engine force terms a mode declares (and so pays for), in order; Thrust is last."""
    ship_indices = [0, 1]
    terms = []
    mu = rules.effective_star_mu
    softening = 0.5 * rules.star_capture
    if mu > 0:
        targets = None if rules.torpedoes_feel_star else ship_indices
        terms.append(forces.PointMass(mu=mu, pos=(0.0, 0.0), softening=softening, particles=targets))
    if rules.mode == "newtonian":
        terms.append(forces.NBodyGravity(G=rules.ship_gravity, softening=rules.hit_box))
    if rules.mode == "electric":
        terms.append(forces.Coulomb(k=rules.coulomb_k, softening=rules.hit_box))
    terms.append(forces.Thrust(particles=ship_indices))  # the engines push the ships only
    return terms


def _rules_vector(rules, rounds, thrust_offset):
    v = np.zeros(core.RN)
    v[core.R_TURN] = rules.turn_rate
    v[core.R_ANG_ACCEL] = rules.angular_accel
    v[core.R_ANG_MOM] = float(rules.angular_momentum)
    v[core.R_THRUST] = rules.thrust
    v[core.R_BURN_MIN] = rules.fuel_burn_min
    v[core.R_BURN_MAX] = rules.fuel_burn_max
    v[core.R_FUEL] = rules.fuel
    v[core.R_SHIP_MASS] = rules.ship_mass
    v[core.R_START] = rules.start_distance
    v[core.R_NTORP] = rules.torpedoes
    v[core.R_RELOAD] = rules.reload
    v[core.R_TLIFE] = rules.torpedo_life
    v[core.R_MUZZLE] = rules.muzzle_speed
    v[core.R_OFFSET] = rules.launch_offset
    v[core.R_TMASS] = rules.torpedo_mass
    v[core.R_HJUMPS] = rules.hyperspace_jumps
    v[core.R_HFRAMES] = rules.hyperspace_frames
    v[core.R_HRECHARGE] = rules.hyperspace_recharge
    v[core.R_HRISK] = rules.hyperspace_risk
    v[core.R_REENTRY] = rules.reentry_speed
    v[core.R_HITBOX] = rules.hit_box
    v[core.R_DIAMOND] = rules.hit_diamond
    v[core.R_DELAY] = rules.post_round_delay
    v[core.R_MAXFRAMES] = rules.max_round_frames
    v[core.R_ROUNDS] = rounds
    v[core.R_MAXEXTRA] = rules.max_extra_rounds
    v[core.R_STAR] = rules.effective_star_mu
    v[core.R_CAPTURE] = rules.star_capture
    v[core.R_STAR_KILLS] = float(rules.star_kills)
    v[core.R_SINGLE] = float(rules.single_shot)
    v[core.R_TORP_STAR] = float(rules.torpedoes_feel_star)
    v[core.R_CHARGE] = rules.charge
    v[core.R_FLIP_CD] = rules.flip_cooldown
    v[core.R_ELECTRIC] = float(rules.mode == "electric")
    v[core.R_THRUST_OFF] = thrust_offset
    return v


def seed_state(seed):
    """A 64-bit stream state from any non-negative int seed (via numpy's SeedSequence)."""
    seed = count_at_least("seed", seed, 0)
    return np.random.SeedSequence(seed).generate_state(1, np.uint64)[0]


class Checkpoint:
    """One match's complete state at one frame, as read-only copies (``Game.checkpoint``).

    It holds the match's row of every array the compiled frame reads and writes: the engine's
    bodies (positions, velocities, masses, charges, radii and the active, test and pinned
    flags), the packed force parameters (the engines' thrust is written there every frame),
    the ships' gauges and counters, the torpedoes' lifetimes, the match's counters and scores
    and its random stream. The arrays every match shares and no frame changes (the rules
    vector, the force layout, the integrator's coefficients) are not copied; ``layout``
    records them, so a checkpoint is only restored into a game whose frames they would step
    identically. ``frame`` is the match's frame number; ``nbytes`` what the copies take.
    """

    __slots__ = ("frame", "arrays", "layout")

    def __init__(self, frame, arrays, layout):
        self.frame = frame
        self.arrays = arrays
        self.layout = layout

    @property
    def nbytes(self):
        return sum(a.nbytes for a in self.arrays)

    def __repr__(self):
        return f"Checkpoint(frame={self.frame}, {self.nbytes} bytes)"


class Game:
    """``len(seeds)`` matches of ``rounds`` rounds each under ``rules``."""

    def __init__(self, rules=None, seeds=(0,), rounds=5):
        rules = Rules() if rules is None else rules
        if not isinstance(rules, Rules):
            raise TypeError(f"rules must be a spacewar.Rules, got {rules!r}")
        count_at_least("rounds", rounds, 1)
        seeds = list(seeds)
        if not seeds:
            raise ValueError("seeds must hold at least one seed (one per match)")
        self.rules = rules
        self.rounds = int(rounds)
        self.seeds = seeds
        m = len(seeds)
        t = rules.torpedoes
        self.n_bodies = nb = 2 + 2 * t
        # one engine system per match, on the torus of side 1; the mode's force terms are
        # declared on it and packed by the engine
        self.batch = batch = Batch(systems=m, dim=2, integrator="symplectic_euler", dt=1.0,
                                   capacity=nb, box=1.0)
        batch.add_many(mass=rules.torpedo_mass, pos=np.zeros((nb, 2)),
                       test=np.arange(nb) >= 2)  # torpedoes feel gravity but exert none
        self.terms = force_terms(rules)
        for term in self.terms:
            batch.add_force(term)
        thrust = self.terms[-1]
        thrust_columns = batch.parameter_columns(thrust, "force")  # written by the rules each frame
        self.state, self.model = batch.kernel_arguments()
        self._revision = batch.revision
        self.rules_vector = _rules_vector(rules, self.rounds, thrust_columns[0])
        self.drifts, self.kicks = core.drift_kick()
        # the game's own state, beside the engine's
        self.ship_gauges = np.zeros((m, 2, core.SF))
        self.ship_counters = np.zeros((m, 2, core.SI), dtype=np.int64)
        self.torp_life = np.zeros((m, 2 * t), dtype=np.int64)
        self.match_state = np.zeros((m, core.MI), dtype=np.int64)
        self.rng = np.array([seed_state(s) for s in seeds], dtype=np.uint64)
        self._actions = np.full((m, 2), core.NOOP, dtype=np.int64)
        core.reset_all(self.pos, self.vel, self.mass, self.charge, self.active, self.ship_gauges,
                       self.ship_counters, self.torp_life, self.match_state, self.rules_vector)
        self.frame_arguments = self.gather_frame_arguments()

    def sync_with_batch(self):
        """Follow a re-pack of the batch (a term's attribute changed, a term or slots added):
        its parameter rows are then a new array, with the thrust at new columns, and the frame
        must write into and step with those, never a stale copy."""
        if self.batch.revision == self._revision:
            return
        self.state, self.model = self.batch.kernel_arguments()
        self.rules_vector[core.R_THRUST_OFF] = self.batch.parameter_columns(self.terms[-1],
                                                                            "force")[0]
        self._revision = self.batch.revision
        self.frame_arguments = self.gather_frame_arguments()

    def gather_frame_arguments(self):
        """What the compiled frame takes after the actions, gathered once (and again after a
        re-pack), not per frame."""
        return (*self.state, *self.model, self.ship_gauges, self.ship_counters, self.torp_life,
                self.match_state, self.rng, self.rules_vector, self.drifts, self.kicks)

    # the engine's arrays of every match: (M, 2, bodies) positions and velocities, (M, bodies)
    # masses, charges and active flags (the batch's storage, which the compiled frame writes)
    pos = property(lambda self: self.state.pos)
    vel = property(lambda self: self.state.vel)
    mass = property(lambda self: self.state.mass)
    charge = property(lambda self: self.state.charge)
    active = property(lambda self: self.state.active)

    # -- stepping -------------------------------------------------------------------
    @property
    def n_matches(self):
        return self.pos.shape[0]

    def step(self, actions=None):
        """One frame of every match. ``actions``: (M, 2) codes, Action objects, or None (no-ops)."""
        if actions is None:
            self._actions[:] = core.NOOP
        else:
            self._actions[:] = self.encode_actions(actions)
        self.sync_with_batch()
        core.step_all(self._actions, *self.frame_arguments)

    def step_codes(self, codes):
        """``step`` with (M, 2) int64 action codes the caller has already checked (the match
        loop's, which come from ``protocol.action_code``): no conversion, no checks."""
        self.sync_with_batch()
        core.step_all(codes, *self.frame_arguments)

    def step_one_codes(self, m, codes, raws):
        """``step_codes`` for match m alone, which also writes what each seat sees next into
        ``raws`` (2, ``raw_length``): the match loop's one compiled call per frame."""
        self.sync_with_batch()
        core.step_one_and_observe(codes, *self.frame_arguments, m, raws)

    def write_raw(self, m, seat, out):
        """``raw_observation(m, seat, out)`` for a caller that owns a right ``out``."""
        state = self.state
        core.write_observation(m, seat, state.pos, state.vel, state.charge, state.active,
                               self.ship_gauges, self.ship_counters, self.torp_life,
                               self.match_state, self.rules_vector, out)
        return out

    def encode_actions(self, actions):
        if isinstance(actions, np.ndarray) and actions.dtype.kind in "iu":
            codes = actions
        else:
            codes = np.array([[a.code() if isinstance(a, Action) else a for a in row]
                              for row in actions], dtype=np.int64)
        if codes.shape != (self.n_matches, 2):
            raise ValueError(f"actions must have shape ({self.n_matches}, 2), got {codes.shape}")
        if codes.min() < 0 or codes.max() >= core.N_ACTIONS:
            raise ValueError(f"action codes must be in [0, {core.N_ACTIONS}), got {codes.min()}..{codes.max()}")
        return codes

    # -- read-out -------------------------------------------------------------------
    @property
    def over(self):
        return self.match_state[:, core.OVER].astype(bool)

    @property
    def scores(self):
        return self.match_state[:, [core.SCORE0, core.SCORE1]].copy()

    @property
    def frame(self):
        return self.match_state[:, core.FRAME].copy()

    def rounds_played(self, m=0):
        return int(self.match_state[m, core.ROUNDS_PLAYED])

    def errored(self, m=0):
        return bool(self.match_state[m, core.ERROR])

    def raw_observation(self, m, seat, out=None):
        """The observation of match ``m`` from seat ``seat`` as a flat float64 array
        (``spacewar.protocol.raw_layout`` names its entries); written into ``out`` if given."""
        if not 0 <= m < self.n_matches or seat not in (0, 1):
            raise ValueError(f"no seat {seat!r} of match {m!r} in {self.n_matches} matches")
        n = raw_length(self.rules)
        if out is None:
            raw = np.empty(n)
        elif (not isinstance(out, np.ndarray) or out.dtype != np.float64 or out.shape != (n,)
              or not out.flags.c_contiguous or not out.flags.writeable):
            raise ValueError(f"out must be a writeable C-contiguous float64 array of shape ({n},), "
                             f"got {type(out).__name__} "
                             f"{getattr(out, 'dtype', '')} {getattr(out, 'shape', '')}")
        else:
            raw = out
        core.write_observation(int(m), int(seat), self.pos, self.vel, self.charge, self.active,
                               self.ship_gauges, self.ship_counters, self.torp_life, self.match_state, self.rules_vector, raw)
        return raw

    def learning_observations(self, out=None):
        """Every match's two seats as learning observations, (M, 2, D) float32, written by
        compiled code into ``out`` if given (``spacewar.game.features.learning_layout`` names the
        D entries)."""

        shape = (self.n_matches, 2, features.learning_length(self.rules))
        if out is None:
            out = np.empty(shape, dtype=np.float32)
        elif (not isinstance(out, np.ndarray) or out.dtype != np.float32 or out.shape != shape
              or not out.flags.c_contiguous or not out.flags.writeable):
            raise ValueError(f"out must be a writeable C-contiguous float32 array of shape {shape}, "
                             f"got {type(out).__name__} {getattr(out, 'dtype', '')} "
                             f"{getattr(out, 'shape', '')}")
        if getattr(self, "_learning_scales", None) is None:
            self._learning_scales = features.learning_scales(self.rules, self.rounds)
        features.write_all_learning(self.pos, self.vel, self.charge, self.active,
                                    self.ship_gauges, self.ship_counters, self.torp_life,
                                    self.match_state, self.rules_vector, self._learning_scales, out)
        return out

    def learning_observation(self, m, seat):
        """One seat's learning observation computed in NumPy from the observation a bot gets
        (``raw_observation``): the reference for ``learning_observations``."""
        return features.learning_vector(self.raw_observation(m, seat), self.rules, self.rounds)

    def observe(self, m, seat):
        """The observation of match ``m`` from seat ``seat``'s side: a fresh object whose arrays
        are read-only, so a bot cannot change the game through it."""
        return observation_from_raw(self.raw_observation(m, seat), self.rules)

    def snapshot(self, m=0):
        """Plain data for drawing match ``m``: ships, torpedoes, score, frame."""
        t = self.rules.torpedoes
        ships = []
        for s in range(2):
            i = self.ship_counters[m, s]
            ships.append({"pos": self.pos[m, :, s].tolist(), "heading": float(self.ship_gauges[m, s, core.HEADING]),
                          "alive": bool(i[core.ALIVE]), "in_hyperspace": bool(i[core.IN_HYPER]),
                          "thrusting": bool(i[core.THRUSTING]), "killed_at": int(i[core.KILLED_AT]),
                          "fuel": float(self.ship_gauges[m, s, core.FUEL]), "torpedoes": int(i[core.TORPS]),
                          "charge": float(self.charge[m, s])})
        live = [b for b in range(2, 2 + 2 * t) if self.active[m, b]]
        return {"frame": int(self.match_state[m, core.FRAME]), "round_frame": int(self.match_state[m, core.ROUND_FRAME]),
                "round": int(self.match_state[m, core.ROUNDS_PLAYED]), "scores": self.scores[m].tolist(),
                "frames_in_finished_rounds": int(self.match_state[m, core.ROUND_FRAMES_TOTAL]),
                "ships": ships,
                "torpedoes": [{"pos": self.pos[m, :, b].tolist(), "owner": (b - 2) // t} for b in live],
                "star": self.rules.effective_star_mu > 0, "over": bool(self.match_state[m, core.OVER])}

    # -- checkpoints --------------------------------------------------------------------
    def _match_rows(self, m):
        """Match m's row of every per-match array the compiled frame reads or writes, as
        writeable views into the game's storage, in a fixed order (see ``Checkpoint``)."""
        state = self.state
        rows = slice(m, m + 1)
        return [state.pos[rows], state.vel[rows], state.mass[rows], state.charge[rows],
                state.radius[rows], state.active[rows], state.test[rows], state.pinned[rows],
                self.model.params[rows], self.ship_gauges[rows], self.ship_counters[rows],
                self.torp_life[rows], self.match_state[rows], self.rng[rows]]

    def _layout(self):
        """What a checkpoint's arrays mean: the shared arrays that every frame reads but none
        changes (rules, rounds and thrust columns in the rules vector; the packed force
        layout; the integrator's coefficients) and the per-match arrays' shapes and types."""
        cached = getattr(self, "_layout_cache", None)
        if cached is not None and cached[0] == self._revision:
            return cached[1]  # shared by every checkpoint of this packing, not one per copy
        model = self.model
        shared = (self.rules_vector, model.kinds, model.param_offsets, model.indices,
                  model.index_offsets, self.drifts, self.kicks)
        shapes = tuple((a.shape[1:], a.dtype.str) for a in self._match_rows(0))
        layout = (tuple(np.ascontiguousarray(a).tobytes() for a in shared), shapes,
                  int(self.state.n), float(self.state.box))
        self._layout_cache = (self._revision, layout)
        return layout

    def _match_index(self, m):
        if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or not 0 <= m < self.n_matches:
            raise ValueError(f"m must be a match index in [0, {self.n_matches}), got {m!r}")
        return int(m)

    def checkpoint(self, m=0):
        """A ``Checkpoint`` of match ``m``: copies of its whole state, to ``restore`` later.

        Restoring it and stepping with the same action codes gives bit-identical states
        (``state_hash``) to the run that made it: the frame is a pure function of these arrays
        and the codes. Each checkpoint is about 5 KB under the 1962 rules (32 torpedoes a
        ship); ``spacewar.replay.timeline`` keeps a bounded number of them to scrub a replay.
        """
        m = self._match_index(m)
        self.sync_with_batch()
        arrays = []
        for row in self._match_rows(m):
            copy = row.copy()
            copy.flags.writeable = False  # a checkpoint restores the same state every time
            arrays.append(copy)
        return Checkpoint(int(self.match_state[m, core.FRAME]), tuple(arrays), self._layout())

    def restore(self, checkpoint, m=0):
        """Put match ``m`` back in the state of ``checkpoint`` (from ``checkpoint`` of this
        game or of another with the same rules and rounds; any match index). Checked before
        anything is changed: a checkpoint of a game with other rules, rounds or force layout
        raises ValueError and leaves the game as it was. The other matches are untouched."""
        if not isinstance(checkpoint, Checkpoint):
            raise TypeError(f"checkpoint must be a spacewar.game.Checkpoint (from "
                            f"Game.checkpoint), got {type(checkpoint).__name__}")
        m = self._match_index(m)
        self.sync_with_batch()
        if checkpoint.layout != self._layout():
            raise ValueError(f"checkpoint of frame {checkpoint.frame} was taken in a game with "
                             "other rules, rounds or force layout; it cannot be restored here")
        for row, saved in zip(self._match_rows(m), checkpoint.arrays):
            row[...] = saved

    def state_hash(self, m=0):
        """SHA-256 of every array of match ``m``: equal hashes mean bit-identical states."""
        h = hashlib.sha256()
        for arr in (self.pos, self.vel, self.mass, self.charge, self.active, self.ship_gauges,
                    self.ship_counters, self.torp_life, self.match_state, self.rng):
            h.update(np.ascontiguousarray(arr[m]).tobytes())
        h.update(self._hashed_parameters(m).tobytes())
        return h.hexdigest()

    def _hashed_parameters(self, m):
        """Match m's force parameters as the state hash has always covered them, so replays
        recorded before the game ran on ``engine.Batch`` still verify: each term's packed
        floats, with the torus side in the pair terms' box entry (the batch's space now holds
        it), and without the parameters of the pair terms' tree method."""
        row = self.model.params[m]
        offsets = self.model.param_offsets
        parts = []
        for k, term in enumerate(self.terms):
            block = row[offsets[k]:offsets[k + 1]].copy()
            if isinstance(term, (forces.NBodyGravity, forces.Coulomb)):
                layout = term.layout(self.batch)
                block[layout["box"][0]] = self.batch.box
                # the tree's parameters (theta, order, method) came later, and a batch's terms
                # sum directly: hashed without them, as before
                block = block[:layout["theta"][0]]
            parts.append(block)
        return np.concatenate(parts)


__all__ = ["Game", "Checkpoint", "force_terms", "seed_state"]
