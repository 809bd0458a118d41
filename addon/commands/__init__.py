"""Sub-commands of `python -m addon`, one module each (discovered by addon/cli.py)."""
