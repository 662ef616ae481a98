"""Fetches PyKrige's test suite from its source distribution on PyPI (``pip download``) and
runs ``tests/test_core.py`` with ``pykrige.ok`` and ``pykrige.uk`` aliased to
``terramesh.pykrige`` (``conftest.py`` beside this script).

    python python/conformance/run.py [--version 1.7.2] [--keep DIR] [pytest args...]

Needs, in the running interpreter: terramesh, PyKrige of the same version (its ``core``,
``kriging_tools`` and 3D classes are used as they are), scipy and pytest. Exit status:
pytest's.
"""

import argparse
import pathlib
import shutil
import subprocess
import sys
import tarfile
import tempfile

HERE = pathlib.Path(__file__).resolve().parent


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    from importlib.metadata import version

    ap.add_argument("--version", default=version("pykrige"), help="default: the installed PyKrige's")
    ap.add_argument("--keep", help="folder to fetch and unpack into (kept)")
    args, rest = ap.parse_known_args()
    work = pathlib.Path(args.keep) if args.keep else pathlib.Path(tempfile.mkdtemp(prefix="pykrige-suite-"))
    work.mkdir(parents=True, exist_ok=True)
    sdist = next(work.glob(f"pykrige-{args.version}.tar.gz"), None)
    if sdist is None:
        subprocess.run(
            [sys.executable, "-m", "pip", "download", f"pykrige=={args.version}", "--no-binary",
             "pykrige", "--no-deps", "--quiet", "-d", str(work)],
            check=True,
        )
        sdist = next(work.glob(f"pykrige-{args.version}.tar.gz"))
    src = work / f"pykrige-{args.version}"
    if not src.is_dir():
        with tarfile.open(sdist) as t:
            members = [m for m in t.getmembers() if m.name.startswith(f"pykrige-{args.version}/tests/")]
            t.extractall(work, members=members)
    suite = work / "suite"
    if suite.exists():
        shutil.rmtree(suite)
    shutil.copytree(src / "tests", suite)
    shutil.copy(HERE / "conftest.py", suite / "conftest.py")
    cmd = [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-rA", str(suite / "test_core.py"), *rest]
    print("running:", " ".join(cmd), flush=True)
    code = subprocess.run(cmd, cwd=suite).returncode
    if not args.keep:
        shutil.rmtree(work, ignore_errors=True)
    return code


if __name__ == "__main__":
    sys.exit(main())
