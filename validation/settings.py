"""How much work each level of the report does.

``full`` is the committed report, ``quick`` the same sections smaller (about a minute and a
half on 2 cores), ``smoke`` a hidden seconds-long level used by the tests.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Level:
    name: str
    # leapfrog cross-check
    cross_orbits: int
    # two-body section
    tb_steps_per_orbit: tuple
    tb_orbits: tuple
    tb_tolerances: tuple
    # energy drift
    drift_orbits: float
    drift_steps_per_orbit: int
    drift_euler_steps_per_orbit: int
    drift_euler_orbits: float
    drift_tolerance: float
    drift_solar_days: float
    drift_solar_dt: float
    drift_samples: int
    # work-precision
    wp_min_steps: int              # fewest steps of a fixed-step run
    wp_max_steps: int              # most steps of a fixed-step run
    wp_points: int                 # sweep points per decade of steps (about)
    wp_tolerances: tuple
    wp_ias15_epsilons: tuple
    wp_repeat_below: float         # repeat a timed run while it is shorter than this (s)
    wp_work_cap: float             # max force evaluations x interacting pairs of one run
    wp_repeats: int
    solar_wp_days: float
    # hard cases
    hc_e099_steps: tuple
    hc_e099_orbits: int
    hc_pyth_dts: tuple
    hc_fig8_periods: int
    hc_fig8_steps: tuple
    hc_spring_ks: tuple
    hc_spring_steps: int
    hc_bisect_iterations: int
    hc_flyby_dts: tuple
    workers: int = 2
    # the planetary and few-body work-precision problems and the engine-against-REBOUND table
    wp_kepler_orbits: int = 100    # Kepler e = 0.9 over this many orbits
    wp_star_particles: int = 200   # test particles about a fixed star ...
    wp_star_orbits: float = 20.0   # ... for this many orbits of a = 1
    wp_pair_seconds: float = 2.0   # time budget of one side-by-side re-timing of a pair


FULL = Level(
    name="full",
    cross_orbits=100,
    tb_steps_per_orbit=(100, 1000, 10000), tb_orbits=(1, 10, 100, 1000),
    tb_tolerances=(1e-6, 1e-9, 1e-12),
    drift_orbits=1e5, drift_steps_per_orbit=500, drift_euler_steps_per_orbit=100000,
    drift_euler_orbits=1e3, drift_tolerance=1e-10, drift_solar_days=1e7, drift_solar_dt=10.0,
    drift_samples=80,
    wp_min_steps=100, wp_max_steps=2_000_000, wp_points=3,
    wp_tolerances=(1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13),
    wp_ias15_epsilons=(1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9),
    wp_repeat_below=0.5, wp_repeats=5, wp_work_cap=2e8, solar_wp_days=1e5,
    hc_e099_steps=(1000, 10000, 100000), hc_e099_orbits=10,
    hc_pyth_dts=(1e-3, 1e-4, 1e-5, 1e-6), hc_fig8_periods=1000, hc_fig8_steps=(30, 100, 1000),
    hc_spring_ks=(1e2, 1e4, 1e6), hc_spring_steps=30_000, hc_bisect_iterations=24,
    hc_flyby_dts=(1e-3, 1e-4, 1e-5),
    wp_pair_seconds=5.0,
)

QUICK = Level(
    name="quick",
    cross_orbits=20,
    tb_steps_per_orbit=(100, 1000), tb_orbits=(1, 10, 100),
    tb_tolerances=(1e-6, 1e-9, 1e-12),
    drift_orbits=1e3, drift_steps_per_orbit=500, drift_euler_steps_per_orbit=10000,
    drift_euler_orbits=1e2, drift_tolerance=1e-10, drift_solar_days=1e6, drift_solar_dt=10.0,
    drift_samples=50,
    wp_min_steps=100, wp_max_steps=200_000, wp_points=3,  # a slope readable on every line
    wp_tolerances=(1e-4, 1e-5, 1e-6, 1e-8, 1e-10, 1e-12),
    wp_ias15_epsilons=(1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-9),
    wp_repeat_below=0.2, wp_repeats=3, wp_work_cap=2e7, solar_wp_days=1e5,
    hc_e099_steps=(1000, 10000), hc_e099_orbits=10,
    hc_pyth_dts=(1e-3, 1e-4), hc_fig8_periods=100, hc_fig8_steps=(30, 100),
    hc_spring_ks=(1e2, 1e6), hc_spring_steps=10_000, hc_bisect_iterations=16,
    hc_flyby_dts=(1e-3, 1e-4),
    wp_pair_seconds=1.0,
)

SMOKE = Level(
    name="smoke",
    cross_orbits=2,
    tb_steps_per_orbit=(100,), tb_orbits=(1, 10), tb_tolerances=(1e-9,),
    drift_orbits=20, drift_steps_per_orbit=100, drift_euler_steps_per_orbit=1000,
    drift_euler_orbits=5, drift_tolerance=1e-8, drift_solar_days=2e4, drift_solar_dt=20.0,
    drift_samples=20,
    wp_min_steps=100, wp_max_steps=3000, wp_points=1,
    wp_tolerances=(1e-5, 1e-8), wp_ias15_epsilons=(1e-3, 1e-9),
    wp_repeat_below=0.0, wp_repeats=1, wp_work_cap=1e6, solar_wp_days=1e4,
    hc_e099_steps=(1000,), hc_e099_orbits=2,
    hc_pyth_dts=(1e-3,), hc_fig8_periods=3, hc_fig8_steps=(100,),
    hc_spring_ks=(1e4,), hc_spring_steps=2000, hc_bisect_iterations=8,
    hc_flyby_dts=(1e-3,),
    wp_kepler_orbits=10, wp_star_particles=20, wp_star_orbits=2.0, wp_pair_seconds=0.05,
)

LEVELS = {"full": FULL, "quick": QUICK, "smoke": SMOKE}
