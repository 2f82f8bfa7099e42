"""The former name of ``validation.hard_cases`` (the study modules bear their report sections'
names): the very same module, so that imports and attributes by the old name keep working."""
import sys

from . import hard_cases

sys.modules[__name__] = hard_cases
