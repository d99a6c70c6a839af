"""``python -m fms_testbed`` = ``fms-testbed``."""

import sys

from fms_testbed.cli import main

sys.exit(main())
