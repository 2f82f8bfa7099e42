"""The former name of ``validation.bench.cluster`` (a section of the bench, now a module of its
package): the very same module, so that imports and attributes by the old name keep working."""
import sys

from .bench import cluster

sys.modules[__name__] = cluster
