"""``python -m compare.cli``: the ``spindle-verify`` command."""

import sys

from compare.cli import main

sys.exit(main())
