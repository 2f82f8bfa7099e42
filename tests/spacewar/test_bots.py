"""The built-in bots: valid answers everywhere, correct aim, no suicide into the star, strength."""
import math

import numpy as np
import pytest

from engine.analytic import kepler, orbital_elements
from spacewar import Action, Game, Rules
from spacewar.game import core
from spacewar.bots import make_bot
from spacewar.bots.chaser import Chaser
from spacewar.bots.dodger import Dodger
from spacewar.bots.geometry import (first_hit, launch_state, lead_intercept, lead_straight,
                                    periapsis, predict_path, ram_escape, safe_heading_near,
                                    safest_heading, steer, torus_delta)
from spacewar.bots.idle import Idle
from spacewar.bots.sniper import Sniper
from spacewar.arena.match import play_match

SMART = ("chaser", "sniper", "dodger")


def set_ship(game, s, pos, vel=(0.0, 0.0), heading=None, m=0):
    game.pos[m, :, s] = pos
    game.vel[m, :, s] = vel
    if heading is not None:
        game.ship_gauges[m, s, core.HEADING] = heading


def add_torpedo(game, owner, pos, vel, ttl, k=0, m=0):
    """Put torpedo slot k of ``owner`` in flight (as if fired earlier)."""
    t = game.rules.torpedoes
    b = 2 + owner * t + k
    game.pos[m, :, b] = pos
    game.vel[m, :, b] = vel
    game.active[m, b] = True
    game.torp_life[m, owner * t + k] = ttl


def run_frames(game, bots, frames, stop_when_over=True):
    """Step ``frames`` frames with bots[seat] (None = no-op) and return the observations count."""
    actions = np.full((1, 2), core.NOOP, dtype=np.int64)
    for _ in range(frames):
        if stop_when_over and game.over[0]:
            break
        for s, bot in enumerate(bots):
            if bot is None:
                actions[0, s] = core.NOOP
                continue
            act = bot.act(game.observe(0, s))
            assert isinstance(act, Action)
            actions[0, s] = act.code()
        game.step(actions)


def alive(game, s):
    return bool(game.ship_counters[0, s, core.ALIVE])


# -- geometry ---------------------------------------------------------------------------
def test_periapsis_matches_orbital_elements():
    mu = 2.5e-7
    rng = np.random.default_rng(3)
    for _ in range(30):
        r = rng.uniform(-0.4, 0.4, 2)
        v = rng.uniform(-1.5e-3, 1.5e-3, 2)
        el = orbital_elements(r, v, mu)
        q = periapsis(r, v, mu)
        approaching = float(r @ v) < 0.0
        if el.energy < 0.0 or approaching:
            assert q == pytest.approx(el.periapsis, rel=1e-6, abs=1e-12)
        else:  # unbound and receding: it only gets farther
            assert q == pytest.approx(float(np.hypot(*r)))
    # vectorised over candidate velocities, and no star means nothing to fall into
    vs = np.array([[0.0, 9.1e-4], [0.0, 0.0], [-1e-3, 0.0]])
    qs = periapsis(np.array([0.3, 0.0]), vs, mu)
    assert qs.shape == (3,)
    assert qs[0] == pytest.approx(0.3, rel=0.02)  # near circular
    assert qs[1] == pytest.approx(0.0, abs=1e-12)  # at rest: radial fall
    assert periapsis(np.array([0.3, 0.0]), vs, 0.0).tolist() == [math.inf] * 3


def test_safety_headings_raise_periapsis():
    mu = 2.5e-7
    pos, vel = np.array([0.2, 0.0]), np.array([-5e-4, 0.0])  # falling straight in
    angle, q = safest_heading(pos, vel, mu, heading=math.pi, dv=2.4e-4)
    assert periapsis(pos, vel, mu) == 0.0 and q > 0.004
    # the best burn is sideways (angular momentum is what keeps a ship off the star)
    assert abs(math.sin(angle)) > 0.5
    # a retrograde burn (it would drop the ship into the star) is refused for the nearest
    # direction that keeps the periapsis up
    pos, vel = np.array([0.25, 0.0]), np.array([0.0, 7.2e-4])
    assert periapsis(pos, vel, mu) > 0.08
    want = -0.5 * math.pi
    assert periapsis(pos, vel + 2.4e-4 * np.array([0.0, -1.0]), mu) < 0.08
    nav, safe = safe_heading_near(pos, vel, mu, want, 2.4e-4, 0.08)
    assert safe
    assert periapsis(pos, vel + 2.4e-4 * np.array([math.cos(nav), math.sin(nav)]), mu) >= 0.08
    assert 0.1 < abs(math.remainder(nav - want, 2 * math.pi)) < math.pi / 2 + 0.2
    # with no star every direction is fine
    assert safe_heading_near(pos, vel, 0.0, want, 2.4e-4, 0.08) == (want, True)


def test_ram_escape():
    assert ram_escape(np.array([0.1, 0.0]), np.array([1e-3, 0.0]), 0.04, 50) is None  # receding
    s = ram_escape(np.array([0.1, 0.01]), np.array([-2e-3, 0.0]), 0.04, 80)
    assert s is not None and s[1] < -0.9  # the other passes above: move down


def test_predict_path_follows_kepler_and_the_game():
    """The predicted path of a coasting ship matches the game's own motion closely."""
    rules = Rules()
    game = Game(rules, seeds=[0], rounds=1)
    set_ship(game, 0, (0.2, 0.05), (1e-4, 9e-4))
    set_ship(game, 1, (-0.3, 0.2), (-1e-4, -6e-4))
    times = np.arange(1.0, 61.0)
    pred = predict_path(game.pos[0, :, 1].copy(), game.vel[0, :, 1].copy(), rules.effective_star_mu,
                        times, rules.star_capture)
    seen = []
    for _ in range(60):
        game.step()
        seen.append(game.pos[0, :, 1].copy())
    err = np.abs(torus_delta(pred, np.array(seen))).max()
    assert err < 2e-4  # far below the hit box (1.2e-2)
    direct, _ = kepler(np.array([-0.3, 0.2]), np.array([-1e-4, -6e-4]), rules.effective_star_mu,
                       times)
    assert np.abs(direct - pred).max() < 1e-4


# -- aim ----------------------------------------------------------------------------------
def test_lead_meets_a_straight_mover_by_direct_computation():
    rules = Rules(star="none")
    off, speed = rules.launch_offset, rules.muzzle_speed
    shooter_p, shooter_v = np.array([0.1, -0.2]), np.array([3e-4, -1e-4])
    target_p, target_v = np.array([0.3, 0.05]), np.array([-8e-4, 1.1e-3])
    t, heading = lead_straight(shooter_p, shooter_v, target_p, target_v, off, speed)
    u = np.array([math.cos(heading), math.sin(heading)])
    torpedo_at_t = shooter_p + off * u + t * (shooter_v + speed * u)
    assert np.allclose(torus_delta(torpedo_at_t, target_p + t * target_v), 0.0, atol=1e-12)
    # the sniper's general solver on the sampled path agrees with the closed form
    times = np.arange(1.0, rules.torpedo_life)
    path = predict_path(target_p, target_v, 0.0, times)
    t2, heading2 = lead_intercept(shooter_p, shooter_v, path, times, off, speed)
    assert t2 == pytest.approx(t, abs=0.01)  # linear interpolation between sampled frames
    assert heading2 == pytest.approx(heading, abs=1e-4)
    # across the torus edge: the nearest image is used
    t3, h3 = lead_straight(np.array([0.45, 0.0]), np.zeros(2), np.array([-0.45, 0.0]), np.zeros(2),
                           off, speed)
    assert h3 == pytest.approx(0.0, abs=1e-9) and t3 == pytest.approx((0.1 - off) / speed)
    # a torpedo on that heading is predicted to hit; one 5 degrees off is not
    p0, v0 = launch_state(type("S", (), {"pos": shooter_p, "vel": shooter_v})(), heading, rules)
    assert first_hit(p0, v0, path, times, rules, 0.0) is not None
    p0, v0 = launch_state(type("S", (), {"pos": shooter_p, "vel": shooter_v})(),
                          heading + math.radians(5), rules)
    assert first_hit(p0, v0, path, times, rules, 0.0) is None


@pytest.mark.parametrize("star", ["none", "heavy"])
def test_sniper_hits_a_coasting_target_in_the_game(star):
    """Placed in range of a coasting idle ship, the sniper kills it with its first torpedo."""
    rules = Rules(star=star)
    game = Game(rules, seeds=[1], rounds=1)
    if star == "none":
        set_ship(game, 0, (-0.1, -0.05), (2e-4, 0.0), heading=1.0)
        set_ship(game, 1, (0.12, 0.1), (-9e-4, 6e-4))  # a straight line
    else:  # both on safe orbits, the target on a circular one
        set_ship(game, 0, (-0.2, 0.0), (0.0, -1.1e-3), heading=0.0)
        set_ship(game, 1, (0.0, 0.2), (-math.sqrt(rules.effective_star_mu / 0.2), 0.0))
    sniper = Sniper()
    for _ in range(200):
        if not alive(game, 1):
            break
        run_frames(game, [sniper, None], 1)
    assert not alive(game, 1)
    assert alive(game, 0)
    assert rules.torpedoes - game.ship_counters[0, 0, core.TORPS] == 1


@pytest.mark.parametrize("target_pos, fires", [((0.2, 0.25), False), ((0.0, 0.1), True)])
def test_sniper_does_not_waste_torpedoes_on_hopeless_shots(target_pos, fires):
    """Without fuel to close in, a target beyond a torpedo's reach (offset + muzzle speed x
    life = 0.40) draws no fire in 150 frames; one within reach does. (The target drifts
    slowly: the heading moves in steps of 3.6 degrees, so a frozen geometry may never offer
    a heading within the sniper's margin.)"""
    rules = Rules(star="none")
    game = Game(rules, seeds=[1], rounds=1)
    set_ship(game, 0, (-0.2, -0.2), (0.0, 0.0), heading=0.0)
    game.ship_gauges[0, 0, core.FUEL] = 0.0
    set_ship(game, 1, target_pos, (2e-4, -1e-4))
    assert (math.hypot(*torus_delta(game.pos[0, :, 0], game.pos[0, :, 1])) < 0.4) == fires
    game.ship_counters[0, 1, core.TORPS] = 0
    run_frames(game, [Sniper(), None], 150)
    used = rules.torpedoes - game.ship_counters[0, 0, core.TORPS]
    assert (used > 0) == fires


def test_sniper_holds_fire_at_a_ship_falling_into_the_star():
    """Idle ships fall into the star; a shot that would arrive after the fall is not taken."""
    rules = Rules()
    game = Game(rules, seeds=[1], rounds=1)
    set_ship(game, 0, (-0.25, 0.0), (0.0, -1.0e-3), heading=0.0)
    set_ship(game, 1, (0.05, 0.0), (-1.5e-3, 0.0))  # 20-odd frames from the star
    sniper = Sniper()
    obs = game.observe(0, 0)
    path = sniper.enemy_path(obs)
    sol = sniper.solve(obs, path)
    assert sol is not None and sniper.doomed_before(obs, path, sol[0])
    game.ship_gauges[0, 0, core.HEADING] = sol[1]
    assert not sniper.fire_ok(game.observe(0, 0), 0, path)


# -- valid answers everywhere ---------------------------------------------------------------
VARIANTS = [
    Rules(),
    Rules(star="light"),
    Rules(star="none"),
    Rules(mode="electric"),
    Rules(mode="newtonian"),
    Rules(angular_momentum=True, single_shot=True),
    Rules(star_kills=False, torpedoes=4),
]


@pytest.mark.parametrize("rules", VARIANTS, ids=lambda r: f"{r.mode}-{r.star}-{r.angular_momentum}")
@pytest.mark.parametrize("name", SMART)
def test_bots_answer_valid_actions(name, rules):
    bot = make_bot(name, seed=5)
    other = make_bot("random", seed=6)
    game = Game(rules, seeds=[2], rounds=2)
    run_frames(game, [bot, other], 250)
    # odd situations: enemy in hyperspace, enemy dead, a torpedo in flight, ship on the star
    obs_states = []
    game.ship_counters[0, 1, core.IN_HYPER] = 1
    game.ship_counters[0, 1, core.HYPER_TIMER] = 30
    game.active[0, 1] = False
    obs_states.append(game.observe(0, 0))
    game.ship_counters[0, 1, core.IN_HYPER] = 0
    game.ship_counters[0, 1, core.ALIVE] = 0
    add_torpedo(game, 1, game.pos[0, :, 0] + 0.05, (-2e-3, -2e-3), 40,
                k=min(3, rules.torpedoes - 1))
    obs_states.append(game.observe(0, 0))
    game.ship_counters[0, 1, core.ALIVE] = 1
    game.active[0, 1] = True
    set_ship(game, 1, (0.0, 0.0), (0.0, 0.0))  # enemy exactly on the star
    obs_states.append(game.observe(0, 0))
    set_ship(game, 0, (0.0, 0.0), (0.0, 0.0))  # me exactly on the star
    obs_states.append(game.observe(0, 0))
    game.ship_counters[0, 0, core.IN_HYPER] = 1
    obs_states.append(game.observe(0, 0))
    game.ship_counters[0, 0, core.ALIVE] = 0
    obs_states.append(game.observe(0, 0))
    for obs in obs_states:
        act = bot.act(obs)
        assert isinstance(act, Action)
    assert bot.act(obs_states[-1]) == Action()  # dead: nothing to do


def test_bots_construct_without_arguments():
    for cls in (Chaser, Sniper, Dodger):
        bot = cls()
        bot.reset()
        assert isinstance(bot.act(Game(Rules(), seeds=[0]).observe(0, 0)), Action)


def test_steer_with_angular_momentum_settles_on_target():
    rules = Rules(angular_momentum=True)

    class Ship:
        heading = 0.0
        angular_velocity = 0.0

    ship = Ship()
    limit = 4.0 * rules.turn_rate
    for _ in range(200):
        turn = steer(ship, 2.0, rules)
        w = ship.angular_velocity + turn * rules.angular_accel
        ship.angular_velocity = min(limit, max(-limit, w))
        ship.heading += ship.angular_velocity
    assert abs(ship.heading - 2.0) < 0.1 and abs(ship.angular_velocity) < 2 * rules.angular_accel


# -- the star --------------------------------------------------------------------------------
@pytest.mark.parametrize("name", SMART)
@pytest.mark.parametrize("seat", [0, 1])
def test_no_suicide_in_the_heavy_star_against_idle(name, seat):
    """A full round against idle (which falls into the star): the bot survives and scores."""
    game = Game(Rules(), seeds=[4], rounds=1)
    bots = [None, None]
    bots[seat] = make_bot(name, seed=1)
    run_frames(game, bots, 3000)
    assert game.over[0]
    assert game.scores[0, seat] == 1 and game.scores[0, 1 - seat] == 0


@pytest.mark.parametrize("name", SMART)
def test_escapes_a_fall_towards_the_star(name):
    """Started falling at the star (periapsis ~0) with a target orbiting far away, the bot
    climbs out and is still alive 1500 frames later; an idle ship in its place dies."""
    rules = Rules()
    mu = rules.effective_star_mu

    def play(bot):
        game = Game(rules, seeds=[3], rounds=1)
        set_ship(game, 0, (0.16, 0.02), (-7e-4, 0.0), heading=math.pi)
        set_ship(game, 1, (-0.35, 0.0), (0.0, -math.sqrt(mu / 0.35)))
        game.ship_counters[0, 1, core.TORPS] = 0  # the target cannot shoot
        run_frames(game, [bot, None], 1500)
        return alive(game, 0) or game.scores[0, 0] == 1

    assert not play(Idle())
    assert play(make_bot(name, seed=0))


# -- the dodger ------------------------------------------------------------------------------
def _torpedo_at(game, target, distance, angle, ttl=90):
    p = game.pos[0, :, 0] + distance * np.array([math.cos(angle), math.sin(angle)])
    v = game.vel[0, :, 0] - 4e-3 * np.array([math.cos(angle), math.sin(angle)])
    add_torpedo(game, 1, p, v, ttl)


@pytest.mark.parametrize("bot_factory, survives", [(Idle, False), (Dodger, True)])
def test_dodger_sidesteps_a_torpedo(bot_factory, survives):
    rules = Rules(star="none")
    game = Game(rules, seeds=[0], rounds=1)
    set_ship(game, 0, (0.0, 0.0), (0.0, 0.0), heading=0.3)
    set_ship(game, 1, (0.4, 0.4), (0.0, 0.0))
    game.ship_counters[0, 1, core.TORPS] = 0
    _torpedo_at(game, 0, 0.3, 2.0)
    run_frames(game, [bot_factory(), None], 100)
    assert alive(game, 0) == survives
    assert game.ship_counters[0, 0, core.HYPER_JUMPS] == 0  # dodged by thrust, no jump


def test_dodger_jumps_as_a_last_resort():
    rules = Rules(star="none")
    game = Game(rules, seeds=[0], rounds=1)
    set_ship(game, 0, (0.0, 0.0), (0.0, 0.0), heading=0.0)
    set_ship(game, 1, (0.4, 0.4), (0.0, 0.0))
    _torpedo_at(game, 0, 0.026, 1.0)
    dodger = Dodger()
    act = dodger.act(game.observe(0, 0))
    assert act.hyperspace
    game.ship_counters[0, 0, core.HYPER_RECHARGE] = 10  # not available: it tries to sidestep instead
    act = dodger.act(game.observe(0, 0))
    assert not act.hyperspace and act.thrust in (True, False)


# -- strength -----------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["chaser", "sniper"])
@pytest.mark.parametrize("opponent", ["idle", "random"])
def test_strength_against_baselines(name, opponent):
    """At least 8 of 10 seeded one-round matches won, 5 in each seat."""
    wins = 0
    for seed in range(5):
        for seat in (0, 1):
            bots = (name, opponent) if seat == 0 else (opponent, name)
            result, _, _ = play_match(*bots, seed=100 + seed, rounds=1, isolation="inline")
            wins += result["winner_seat"] == seat
    assert wins >= 8
