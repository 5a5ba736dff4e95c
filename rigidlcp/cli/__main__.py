"""`python -m rigidlcp.cli ARGS` is `rigidlcp ARGS` (for environments without the script)."""

import sys

from .main import main

sys.exit(main())
