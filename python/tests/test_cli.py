"""The ``terramesh`` command that ``pip install ./python`` installs (the console script
``terramesh._cli:main``, run from the package's own compiled library): it works with no other
terramesh on PATH and no TERRAMESH_BIN, is the same command as the cargo-built binary, handles
Ctrl-C like it, and drives ``python -m terramesh.dask`` on its own."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import sysconfig
import time

import pytest

import terramesh

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "haut-barr" / "terramesh.toml"
SCRIPTS = pathlib.Path(sysconfig.get_path("scripts"))
SCRIPT = SCRIPTS / ("terramesh.exe" if os.name == "nt" else "terramesh")


def clean_env():
    """No cargo target folder on PATH and no TERRAMESH_BIN: only this interpreter's scripts
    folder and the system's."""
    env = {k: v for k, v in os.environ.items() if k not in ("TERRAMESH_BIN", "TERRAMESH")}
    env["PATH"] = os.pathsep.join([str(SCRIPTS), "/usr/bin", "/bin"])
    return env


def run(*args, check=True, input=None):
    p = subprocess.run(
        [str(a) for a in args], capture_output=True, text=True, env=clean_env(), input=input
    )
    if check:
        assert p.returncode == 0, p.stderr
    return p


@pytest.fixture(scope="module")
def script():
    if not SCRIPT.is_file():
        pytest.fail(f"{SCRIPT} missing: pip install ./python installs the terramesh command")
    # pip's console script (a Python launcher), not a binary copied there.
    assert SCRIPT.read_bytes()[:2] == b"#!" and b"terramesh._cli" in SCRIPT.read_bytes()
    return SCRIPT


def test_the_installed_command_runs_without_cargo_or_terramesh_bin(script):
    v = run("terramesh", "--version")
    assert v.stdout.strip() == f"terramesh {terramesh.__version__}"
    h = run("terramesh", "tiles", "--help").stdout
    for sub in ("plan", "build", "merge", "slurm"):
        assert f"\n  {sub}" in h, h
    assert run(sys.executable, "-m", "terramesh", "--version").stdout == v.stdout
    d = run(sys.executable, "-m", "terramesh.dask", "--help").stdout
    assert "--scheduler" in d and "TERRAMESH_BIN" in d


def test_exit_codes_and_messages_are_the_binarys(script, tmp_path):
    # A usage error: clap's message and code 2.
    p = run("terramesh", "tiles", "--no-such-flag", check=False)
    assert p.returncode == 2 and "unexpected argument '--no-such-flag'" in p.stderr
    assert p.stdout == ""
    # An error of the command: one line, code 1.
    p = run("terramesh", "build", tmp_path / "missing.toml", "-o", tmp_path / "out", check=False)
    assert p.returncode == 1 and p.stderr.startswith("terramesh: error: "), p.stderr
    assert "missing.toml" in p.stderr and not (tmp_path / "out").exists()
    # The command's standard output reaches a pipe whole (flushed before Python exits).
    p = run("terramesh", "convert", "--to", "utm", "-", input="lat,lon\n48.7224,7.3368\n")
    lines = p.stdout.splitlines()
    assert len(lines) == 2 and lines[1].startswith("48.7224,7.3368,377676.93"), p.stdout
    assert "32N" in lines[1]


def test_same_help_as_the_cargo_binary(script):
    binary = ROOT / "target" / "release" / "terramesh"
    if not binary.is_file():
        pytest.skip(f"skipped: {binary} missing (cargo build --release -p terramesh-cli)")
    for args in (["--help"], ["tiles", "--help"], ["build", "--help"], ["--version"]):
        ours = run("terramesh", *args).stdout
        theirs = run(binary, *args).stdout
        assert ours == theirs, args


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_ctrl_c_stops_the_command_as_it_stops_the_binary(script, tmp_path, sig):
    out = tmp_path / "out"
    child = subprocess.Popen(
        ["terramesh", "build", str(EXAMPLE), "-o", str(out), "--quiet",
         "--set", "sampling.rows=300", "--set", "sampling.cols=150"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=clean_env(),
    )
    t = time.time()
    # Once the build writes into its staging folder (beside `out`), it is deep in the work.
    while not any(p.is_dir() and any(p.iterdir()) for p in tmp_path.iterdir()):
        assert child.poll() is None, child.communicate()[1]
        assert time.time() - t < 120, "no staging folder"
        time.sleep(0.005)
    sent = time.time()
    child.send_signal(sig)
    _, err = child.communicate(timeout=60)
    assert time.time() - sent < 5, "took too long to stop"
    assert child.returncode == 130, err
    assert "interrupted: unfinished files removed" in err, err
    assert list(tmp_path.iterdir()) == [], "a staging folder or an output was left"


def test_tiles_slurm_scripts_run_the_installed_command(script, tmp_path):
    plan = tmp_path / "plan"
    run("terramesh", "tiles", "plan", EXAMPLE, "--tile-size", "150m", "-o", plan, "--quiet")
    run("terramesh", "tiles", "slurm", plan, "--partition", "compute")
    sbatch = (plan / "slurm" / "tiles.sbatch").read_text()
    assert str(SCRIPT) in sbatch, sbatch
    assert sys.executable not in sbatch.replace(str(SCRIPT), "")


def test_the_dask_driver_runs_with_the_installed_command_alone(script, tmp_path):
    pytest.importorskip("distributed")
    plan, out = tmp_path / "plan", tmp_path / "out"
    run("terramesh", "tiles", "plan", EXAMPLE, "--tile-size", "150m", "-o", plan, "--quiet")
    ids = [t["id"] for t in json.loads((plan / "tiles.json").read_text())["tiles"]]
    assert len(ids) >= 2
    p = run(sys.executable, "-m", "terramesh.dask", plan, "--scheduler", "local", "-o", out)
    assert all(f"tile {i}" in p.stdout for i in ids), p.stdout
    assert "merged into" in p.stdout, p.stdout
    state = {t["id"]: t["state"] for t in json.loads((plan / "tiles.json").read_text())["tiles"]}
    assert set(state.values()) == {"done"}, state
    assert (out / "dsm.vtu").stat().st_size > 1000
