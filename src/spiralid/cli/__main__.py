"""``python -m spiralid.cli``."""

import sys

from . import main

sys.exit(main())
