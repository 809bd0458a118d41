"""`python -m addon ...`: the command line (ARCHITECTURE.md section 7)."""

import sys

from .cli import main

sys.exit(main())
