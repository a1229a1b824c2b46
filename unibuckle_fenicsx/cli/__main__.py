"""``python -m unibuckle_fenicsx.cli``: the command line, as ``unibuckle``."""

import sys

from unibuckle_fenicsx.cli import main

sys.exit(main())
