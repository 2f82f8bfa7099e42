import sys

from spacewar.cli import main

sys.exit(main())
