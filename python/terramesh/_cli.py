"""The ``terramesh`` command installed by pip: the command-line tool of the Rust workspace,
run from the package's own compiled library (``terramesh._terramesh``), so no separately
built binary and no cargo are needed.

``terramesh ARGS`` (the console script) and ``python -m terramesh ARGS`` are the same
command as the binary ``cargo build -p terramesh-cli`` makes: the same subcommands, output,
exit codes and Ctrl-C handling.
"""

from __future__ import annotations

import os
import shutil
import sys
import sysconfig
from typing import List, Optional, Sequence

__all__ = ["main", "command"]

_NAME = "terramesh" + (".exe" if os.name == "nt" else "")


def _script() -> Optional[str]:
    """The console script that runs this package's command, if pip installed one: the one
    being run, else the one in this interpreter's scripts folder, else ``terramesh`` on
    ``PATH``."""
    arg0 = sys.argv[0] if sys.argv else ""
    if os.path.basename(arg0) in ("terramesh", _NAME) and os.path.isfile(arg0):
        return os.path.abspath(arg0)
    scripts = sysconfig.get_path("scripts")
    if scripts and os.path.isfile(os.path.join(scripts, _NAME)):
        return os.path.join(scripts, _NAME)
    return shutil.which("terramesh")


def command() -> List[str]:
    """The command line that runs this package's ``terramesh`` in a new process (its console
    script, or ``python -m terramesh`` where none is installed).

    >>> c = command()
    >>> os.path.basename(c[0]) in ("terramesh", "terramesh.exe") or c[1:] == ["-m", "terramesh"]
    True
    """
    scripts = sysconfig.get_path("scripts")
    script = os.path.join(scripts, _NAME) if scripts else None
    if script and os.path.isfile(script):
        return [script]
    return [sys.executable, "-m", "terramesh"]


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Runs ``terramesh`` with ``argv`` (default: this process's arguments) and returns its
    exit code. It installs the command's Ctrl-C handler for the rest of the process: it is a
    process's main, not a function to call from a Python session (run ``command()`` in a
    subprocess there).
    """
    from ._terramesh import cli

    args = list(sys.argv[1:] if argv is None else argv)
    return cli(["terramesh", *args], _script())


if __name__ == "__main__":
    sys.exit(main())
