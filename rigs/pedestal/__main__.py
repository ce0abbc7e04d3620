"""``python -m rigs.pedestal``: see ``rigs.pedestal.cli``."""
import sys

from .cli import main

sys.exit(main())
