"""``python -m terramesh ARGS``: the ``terramesh`` command (see :mod:`terramesh._cli`)."""

import sys

if __name__ == "__main__":
    from ._cli import main

    sys.exit(main())
