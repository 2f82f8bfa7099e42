"""The former name of ``validation.two_body`` (the study modules bear their report sections'
names): the very same module, so that imports and attributes by the old name keep working."""
import sys

from . import two_body

sys.modules[__name__] = two_body
