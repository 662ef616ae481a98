"""Tiled builds on a Dask cluster: one task per tile of a plan, with retries, then the merge.

A plan is made by ``terramesh tiles plan PROJECT.toml --tile-size 10km -o PLAN/``; each task
runs ``terramesh tiles build PLAN/ --tile ID`` on a worker, and the merge task ``terramesh
tiles merge PLAN/ -o OUT/``. The command is the ``binary`` argument or ``$TERRAMESH_BIN``
when given, else the ``terramesh`` command of this package as installed where the task runs
(``pip install`` puts it beside the worker's Python: no cargo, no separate binary). The plan folder must be on a file system every
worker sees. Tiles are independent and their builds atomic: a task that dies with its worker
is run again by Dask elsewhere, and a tile that fails is reported and can be built again alone
(``build_tiles(plan, client, tiles=["x1y1"])``).

>>> from dask.distributed import Client, LocalCluster      # doctest: +SKIP
>>> client = Client(LocalCluster(n_workers=2))             # doctest: +SKIP
>>> build_tiles("plan/", client, merge_to="out/")          # doctest: +SKIP

On an HPC cluster, with dask-jobqueue::

    from dask_jobqueue import SLURMCluster
    cluster = SLURMCluster(queue="compute", cores=4, memory="8GB", walltime="01:00:00")
    cluster.scale(jobs=16)
    build_tiles("plan/", Client(cluster), merge_to="out/")

From the shell: ``python -m terramesh.dask PLAN/ --scheduler tcp://host:8786 -o OUT/``.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import uuid
from dataclasses import dataclass, field

__all__ = ["TileReport", "build_tiles", "find_binary", "main"]


def find_binary(binary: str | None = None) -> str:
    """The ``terramesh`` command: ``binary``, else ``$TERRAMESH_BIN``, else the console script
    this package installed beside the running Python, else ``terramesh`` on ``PATH``; a
    ``FileNotFoundError`` saying how to give it otherwise.

    >>> find_binary("/bin/sh")
    '/bin/sh'
    """
    from ._cli import command

    script = command()
    for candidate in (
        binary,
        os.environ.get("TERRAMESH_BIN"),
        script[0] if len(script) == 1 else None,
        shutil.which("terramesh"),
    ):
        if candidate:
            return candidate
    raise FileNotFoundError(
        "no terramesh command: pip install the terramesh package (it installs one), put one "
        "on PATH, set TERRAMESH_BIN, or pass binary="
    )


def _command(binary: str | None) -> list[str]:
    """The command line of ``terramesh`` where this runs (on a worker for a task):
    ``binary``, else ``$TERRAMESH_BIN``, else this package's own command."""
    from ._cli import command

    given = binary or os.environ.get("TERRAMESH_BIN")
    return [given] if given else command()


def _run(command: list[str], args: list[str]) -> str:
    """Runs ``command`` with ``args``; a ``RuntimeError`` with its message when it fails."""
    p = subprocess.run([*command, *args], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(args[:3])} {' '.join(args[3:])}: {p.stderr.strip()}")
    return p.stdout.strip()


def _build_one(binary: str | None, plan: str, tile: str) -> str:
    return _run(_command(binary), ["tiles", "build", plan, "--tile", tile])


def _merge(binary: str | None, plan: str, out: str, _built: list) -> str:
    return _run(_command(binary), ["tiles", "merge", plan, "-o", out])


@dataclass
class TileReport:
    """What :func:`build_tiles` did: the tiles built (with the binary's message), those that
    failed (with the error, as the manifest records it too), and the merge's message when it
    ran."""

    built: dict = field(default_factory=dict)
    failed: dict = field(default_factory=dict)
    merged: str | None = None

    @property
    def ok(self) -> bool:
        """Whether every tile was built."""
        return not self.failed


def _tile_ids(plan: str) -> list[str]:
    path = os.path.join(plan, "tiles.json")
    try:
        with open(path, encoding="utf-8") as f:
            manifest = json.load(f)
    except OSError as e:
        raise FileNotFoundError(
            f"{path}: {e.strerror}; make a plan first with terramesh tiles plan"
        ) from None
    return [t["id"] for t in manifest["tiles"]]


def build_tiles(
    plan,
    client,
    *,
    merge_to=None,
    tiles=None,
    retries: int = 2,
    binary: str | None = None,
) -> TileReport:
    """Builds the tiles of ``plan`` on the ``dask.distributed`` ``client``, one task per tile
    (``retries`` more tries each; a task on a worker that dies is run again elsewhere), and,
    when every tile is built and ``merge_to`` is given, merges them there in one last task.

    ``tiles`` limits the build to those ids (e.g. a failed one); tiles already done are left as
    they are by ``terramesh tiles build`` itself. Failures do not stop the other tiles: they
    are returned in :attr:`TileReport.failed`, and the merge does not run.
    """
    from dask.distributed import wait

    plan = os.path.abspath(os.fspath(plan))
    # The client's TERRAMESH_BIN, as before; else each worker runs its own package's command.
    exe = binary or os.environ.get("TERRAMESH_BIN")
    ids = list(tiles) if tiles is not None else _tile_ids(plan)
    # One key per call and tile: a key reused while the scheduler still holds the last call's
    # task (a failed tile built again at once) would return that task's result, not a new one.
    run = uuid.uuid4().hex[:8]
    futures = {
        tid: client.submit(
            _build_one,
            exe,
            plan,
            tid,
            key=f"terramesh-tile-{tid}-{run}",
            retries=retries,
            pure=False,
        )
        for tid in ids
    }
    wait(list(futures.values()))
    report = TileReport()
    for tid, fut in futures.items():
        # `result()`, not the status after `wait`: a task whose worker died may still read as
        # lost or pending there and then finish on another worker (its exception was None).
        try:
            report.built[tid] = fut.result()
        except Exception as e:  # the tile's own error, after its retries
            report.failed[tid] = str(e)
    if merge_to is not None and report.ok:
        out = os.path.abspath(os.fspath(merge_to))
        report.merged = client.submit(
            _merge, exe, plan, out, list(futures.values()), retries=retries, pure=False
        ).result()
    return report


def main(argv=None) -> int:
    """``python -m terramesh.dask PLAN/ --scheduler ADDRESS [-o OUT/]``."""
    ap = argparse.ArgumentParser(
        prog="python -m terramesh.dask",
        description="Build the tiles of a terramesh plan on a Dask cluster, then merge them.",
    )
    ap.add_argument("plan", help="the plan folder (terramesh tiles plan ... -o PLAN/)")
    ap.add_argument(
        "--scheduler",
        required=True,
        help="the scheduler's address (tcp://host:8786), or 'local' for a LocalCluster here",
    )
    ap.add_argument("-o", "--output", help="merge into this folder when every tile is built")
    ap.add_argument("--tile", action="append", help="build only this tile (repeatable)")
    ap.add_argument("--retries", type=int, default=2, help="more tries per tile (default 2)")
    ap.add_argument(
        "--binary",
        help="the terramesh command (default: $TERRAMESH_BIN, else this package's own)",
    )
    a = ap.parse_args(argv)
    _tile_ids(a.plan)  # a missing plan is reported before a cluster is started
    from dask.distributed import Client

    client = Client() if a.scheduler == "local" else Client(a.scheduler)
    try:
        r = build_tiles(
            a.plan, client, merge_to=a.output, tiles=a.tile, retries=a.retries, binary=a.binary
        )
    finally:
        client.close()
    for tid, msg in r.built.items():
        print(msg or f"tile {tid} built")
    for tid, why in r.failed.items():
        print(f"tile {tid} failed: {why}", file=sys.stderr)
    if r.merged:
        print(r.merged)
    return 0 if r.ok else 1


if __name__ == "__main__":
    sys.exit(main())
