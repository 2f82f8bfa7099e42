"""engine.space: one wrap and one nearest image, the same bits from Python and compiled code."""
import numpy as np
import pytest
from numba import njit

from engine import space


@njit(cache=False)
def _compiled(x, side):
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = space.wrap_scalar(x[i], side)
    return out


@njit(cache=False)
def _compiled32(x, side):
    out = np.empty_like(x)
    for i in range(x.shape[0]):
        out[i] = space.image(x[i], side, np.float32(0.5))
    return out


@pytest.mark.parametrize("side", [1.0, 0.3, 10.0, 2.0 ** -7, 123.456])
def test_python_and_compiled_wraps_agree_to_the_bit_and_land_in_the_box(side):
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.normal(0.0, 5.0 * side, 20000), [0.5 * side, -0.5 * side, 0.0, -0.0]])
    python = space.wrap(x, side)
    np.testing.assert_array_equal(python, _compiled(x, side))
    np.testing.assert_array_equal(python, space.nearest_image(x, side))
    assert np.all(python >= -0.5 * side - 1e-12 * side) and np.all(python <= 0.5 * side)
    # a wrapped value differs from the original by whole periods
    periods = (x - python) / side
    np.testing.assert_allclose(periods, np.round(periods), atol=1e-9 * np.abs(x).max() / side)
    assert space.wrap(float(x[0]), side) == python[0]  # floats as arrays
    x32 = x.astype(np.float32)
    assert _compiled32(x32, np.float32(side)).dtype == np.float32  # stays in single precision


def test_open_space_changes_nothing():
    x = np.array([-3.5, 0.25, 7.0])
    np.testing.assert_array_equal(space.wrap(x, 0.0), x)
    np.testing.assert_array_equal(_compiled(x, 0.0), x)
    assert space.check_box(None) == 0.0 == space.check_box(0)
    with pytest.raises(ValueError, match="box must be >= 0, got -2.0"):
        space.check_box(-2.0)
