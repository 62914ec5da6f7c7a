"""``python -m tfloc.cli`` = ``tfloc``."""

import sys

from . import main

sys.exit(main())
