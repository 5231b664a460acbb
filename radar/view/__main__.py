"""``python -m radar.view ...`` is ``radar view ...``."""

import sys

from radar.view.cli import main

sys.exit(main())
