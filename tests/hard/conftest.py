"""tests/hard: the helpers module `hard_scenes` sits beside the tests (no package: importlib mode)."""

import sys
from pathlib import Path

HERE = str(Path(__file__).resolve().parent)
if HERE not in sys.path:
    sys.path.insert(0, HERE)
