"""``python -m compare``: the same as the ``spindle-verify`` command."""

import sys

from compare.entry import main

sys.exit(main())
