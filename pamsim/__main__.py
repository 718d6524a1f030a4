"""``python -m pamsim`` is the ``pamsim`` command."""

import sys

from .cli import main

sys.exit(main())
