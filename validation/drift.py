"""The former name of ``validation.energy_drift`` (the study modules bear their report sections'
names): the very same module, so that imports and attributes by the old name keep working."""
import sys

from . import energy_drift

sys.modules[__name__] = energy_drift
