"""``python -m unibuckle_fenicsx.cli``: the command line, as ``unibuckle``."""

import sys

from unibuckle_fenicsx.cli import main

if __name__ == "__main__":  # importing the module (autodoc does) runs nothing
    sys.exit(main())
