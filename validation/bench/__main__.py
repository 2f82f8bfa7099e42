"""``python -m validation.bench``: the same as ``python -m validation bench``."""
import sys

from . import main

sys.exit(main())
