"""``python -m tfloc.cli``."""

import sys

from . import main

sys.exit(main())
