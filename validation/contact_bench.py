"""The former name of ``validation.bench.contact`` (a section of the bench, now a module of its
package): the very same module, so that imports and attributes by the old name keep working."""
import sys

from .bench import contact

sys.modules[__name__] = contact
