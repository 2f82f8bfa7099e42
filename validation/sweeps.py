"""The former name of ``validation.work_precision`` (the study modules bear their report sections'
names): the very same module, so that imports and attributes by the old name keep working."""
import sys

from . import work_precision

sys.modules[__name__] = work_precision
