"""`python3 -m hmpm_client ...`: see cli.py."""

import sys

from .cli import main

sys.exit(main())
