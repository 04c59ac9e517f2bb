"""``python -m validation.cli``: the ``contactlab`` command."""

import sys

from . import main

sys.exit(main())
