"""Kriging, IDW, cross-validation and variograms against PyKrige, the independent reference."""

import json
import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest
from pykrige.ok import OrdinaryKriging as PkOK
from pykrige.uk import UniversalKriging as PkUK

import terramesh
from terramesh import Variogram


def test_universal_kriging_matches_pykrige(field):
    x, y, z = field
    xt, yt = np.meshgrid(np.linspace(100, 1900, 30), np.linspace(100, 1400, 20))
    xt, yt = xt.ravel(), yt.ravel()
    pk = PkUK(x, y, z, variogram_model="spherical", variogram_parameters=[120.0, 900.0, 2.0],
              drift_terms=["regional_linear"])
    zr, sr = pk.execute("points", xt, yt)
    v = Variogram("spherical", psill=118.0, range=900.0, nugget=2.0)
    est, var = terramesh.krige(x, y, z, xt, yt, method="uk", drift="linear", variogram=v)
    np.testing.assert_allclose(est, zr, rtol=0, atol=1e-7)
    np.testing.assert_allclose(var, sr, rtol=1e-8, atol=1e-8)


def test_ordinary_kriging_with_a_neighbourhood_matches_pykrige(field):
    x, y, z = field
    rng = np.random.default_rng(3)
    xt, yt = rng.uniform(0, 2000, 500), rng.uniform(0, 1500, 500)
    pk = PkOK(x, y, z, variogram_model="exponential", variogram_parameters=[100.0, 600.0, 0.0])
    zr, sr = pk.execute("points", xt, yt, n_closest_points=24, backend="loop")
    v = Variogram("exponential", psill=100.0, range=600.0)
    est, var = terramesh.krige(x, y, z, xt, yt, method="ok", variogram=v, neighbors=24)
    np.testing.assert_allclose(est, zr, atol=1e-7)
    np.testing.assert_allclose(var, sr, rtol=1e-7, atol=1e-7)


def test_gaussian_range_is_converted_from_pykrige(field):
    x, y, z = field
    pk = PkOK(x, y, z, variogram_model="gaussian", variogram_parameters=[100.0, 700.0, 1.0])
    zr, _ = pk.execute("points", np.array([555.0]), np.array([444.0]))
    v = Variogram("gaussian", psill=99.0, range=700.0 * 4 * np.sqrt(3) / 7, nugget=1.0)
    est = terramesh.krige(x, y, z, [555.0], [444.0], method="ok", variogram=v, return_variance=False)
    assert est[0] == pytest.approx(zr[0], abs=1e-6)


def test_exact_at_data_and_scalar_shapes(field):
    x, y, z = field
    v = Variogram("spherical", 100.0, 800.0)
    est, var = terramesh.krige(x, y, z, x[:5], y[:5], variogram=v)
    np.testing.assert_allclose(est, z[:5], atol=1e-9)
    assert np.all(np.abs(var) < 1e-9)
    e, s = terramesh.krige(x, y, z, 500.0, 500.0, variogram=v)
    assert isinstance(e, float) and s > 0


def test_idw_matches_its_formula(field):
    x, y, z = field
    xt, yt = np.array([321.0, 1700.0]), np.array([222.0, 1000.0])
    d = np.hypot(xt[:, None] - x[None, :], yt[:, None] - y[None, :])
    w = d**-2.0
    ref = (w @ z) / w.sum(axis=1)
    np.testing.assert_allclose(terramesh.idw(x, y, z, xt, yt), ref, rtol=1e-12)
    near = np.argsort(d, axis=1)[:, :8]
    wk = np.take_along_axis(w, near, 1)
    refk = (wk * z[near]).sum(1) / wk.sum(1)
    np.testing.assert_allclose(terramesh.idw(x, y, z, xt, yt, neighbors=8), refk, rtol=1e-12)


def test_leave_one_out_matches_refitting_without_each_point(field):
    x, y, z = field
    v = Variogram("exponential", 100.0, 700.0)
    cv = terramesh.cross_validate(x, y, z, method="ok", variogram=v)
    for i in (0, 17, 299):
        keep = np.arange(len(x)) != i
        e, s = terramesh.krige(x[keep], y[keep], z[keep], x[i], y[i], method="ok", variogram=v)
        assert cv.estimate[i] == pytest.approx(e, abs=1e-8)
        assert cv.variance[i] == pytest.approx(s, rel=1e-8)
    assert cv.n == 300 and cv.rmse == pytest.approx(np.sqrt(np.mean((cv.estimate - z) ** 2)))


def test_variogram_fit_recovers_a_known_model():
    truth = Variogram("spherical", psill=10.0, range=300.0, nugget=2.0)
    x, y = np.meshgrid(np.arange(0, 1000, 25.0), np.arange(0, 1000, 25.0))
    x, y = x.ravel(), y.ravel()
    # Data whose experimental variogram is not needed to be exact: fit the model's own gamma
    # through the lag classes of a field simulated by the Cholesky factor of its covariance.
    rng = np.random.default_rng(11)
    sub = rng.choice(len(x), 700, replace=False)
    xs, ys = x[sub], y[sub]
    d = np.hypot(xs[:, None] - xs[None, :], ys[:, None] - ys[None, :])
    c = 12.0 - truth.gamma(d.ravel()).reshape(d.shape)
    np.fill_diagonal(c, 12.0)
    zs = np.linalg.cholesky(c + 1e-9 * np.eye(len(xs))) @ rng.standard_normal(len(xs))
    # fit="wls": this is the lag-class fit's recovery of the model; the default, wls-loo,
    # chooses the parameters that predict best by leave-one-out (here a range of 707 m).
    v = Variogram.fit(xs, ys, zs, model="spherical", lags=20, max_dist=600.0, fit="wls")
    assert v.model == "spherical"
    assert 150 < v.range < 600 and v.sill == pytest.approx(12.0, rel=0.5)
    assert v.fit_info["fit"]["rmse"] >= 0 and len(v.fit_info["experimental"]) > 10
    auto = Variogram.fit(xs, ys, zs)
    assert auto.fit_info["candidates"]


def test_variogram_fit_by_reml_is_the_clis_fit(tmp_path):
    # The same data through `terramesh variogram --fit reml` (the binary CI builds) and
    # through Variogram.fit(fit="reml"): one library function, so the same model and the
    # same candidates, and the model is the candidate of least AIC.
    root = pathlib.Path(__file__).resolve().parents[2]
    binary = os.environ.get("TERRAMESH_BIN") or str(root / "target" / "release" / "terramesh")
    rng = np.random.default_rng(5)
    x, y = rng.uniform(0, 2000, 500), rng.uniform(0, 2000, 500)
    z = 40 * np.sin(x / 300) * np.cos(y / 400) + x / 50 + rng.normal(0, 0.5, 500)
    kinds = ["spherical", "exponential", "gaussian", "matern", "power", "linear", "nugget"]
    v = Variogram.fit(x, y, z, fit="reml", drift="linear")
    sel = v.fit_info["selection"]
    assert (sel["method"], sel["drift"], sel["points"], sel["blocks"]) == ("reml", "linear", 500, 2)
    cands = [c for c in v.fit_info["candidates"] if c["fit"] is not None]
    assert len(cands) > len(kinds)  # the models alone and the nested pairs
    chosen = min(cands, key=lambda c: c["aic"])
    assert chosen["fit"]["variogram"]["nugget"] == v.nugget
    exact = Variogram.fit(x, y, z, fit="reml", reml_block=0)
    assert exact.fit_info["selection"]["blocks"] == 1
    if not os.path.exists(binary):
        if os.environ.get("CI"):
            pytest.fail(f"{binary} missing: cargo build --release -p terramesh-cli first")
        pytest.skip(f"skipped: {binary} missing (cargo build --release -p terramesh-cli)")
    csv = tmp_path / "d.csv"
    np.savetxt(csv, np.column_stack([x, y, z]), delimiter=",", header="x,y,z", comments="",
               fmt="%.17g")
    out = tmp_path / "v.json"
    p = subprocess.run([binary, "variogram", "--data", str(csv), "--fit", "reml", "--drift",
                        "linear", "-o", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    cli = json.loads(out.read_text())
    assert Variogram.from_json(out) == v
    assert cli["selection"] == sel
    assert [c.get("aic") for c in cli["candidates"]] == [c.get("aic") for c in v.fit_info["candidates"]]


def test_variogram_fit_refuses_a_bad_fit_or_drift_naming_it():
    x, y = np.arange(50.0), np.arange(50.0) % 7
    with pytest.raises(terramesh.InputError, match='fit: .*"mle".*reml, wls, loo or wls-loo'):
        Variogram.fit(x, y, x, fit="mle")
    with pytest.raises(terramesh.InputError, match='drift: .*"cubic"'):
        Variogram.fit(x, y, x, fit="reml", drift="cubic")


def test_variogram_fit_is_checked_by_the_plan_naming_its_keywords_and_fits_as_the_cli(tmp_path):
    # Variogram.fit lowers its keywords into the plan of `terramesh variogram`: the model to
    # fit is checked by the plan's one check before any lag class is computed (so before the
    # kernel's refusal of max_points=1), worded with the keyword `model`.
    x, y = np.arange(50.0), np.arange(50.0) % 7
    for bad in ("cubic", "spherical+cubic", "nugget+power"):
        with pytest.raises(terramesh.InputError, match=rf"^model '{re.escape(bad)}': "):
            Variogram.fit(x, y, x, model=bad, max_points=1)
    with pytest.raises(terramesh.InputError, match=r"^lags 0: "):
        Variogram.fit(x, y, x, lags=0)
    with pytest.raises(terramesh.InputError, match=r"max.points = 1: must be at least 2"):
        Variogram.fit(x, y, x, max_points=1)
    # A normal fit is the CLI's: the same file but for the data's name and the lag summary's
    # max_dist (the CLI records the last class's bound, Python the keyword given).
    rng = np.random.default_rng(3)
    x, y = rng.uniform(0, 1000, 200), rng.uniform(0, 1000, 200)
    z = np.sin(x / 150) + np.cos(y / 200)
    py = Variogram.fit(x, y, z, model="spherical+exponential", lags=12, weighting="pairs")
    auto = Variogram.fit(x, y, z)
    assert py.fit_info["fit"]["weights"] == "pairs" and auto.fit_info["candidates"]
    root = pathlib.Path(__file__).resolve().parents[2]
    binary = os.environ.get("TERRAMESH_BIN") or str(root / "target" / "release" / "terramesh")
    if not os.path.exists(binary):
        if os.environ.get("CI"):
            pytest.fail(f"{binary} missing: cargo build --release -p terramesh-cli first")
        pytest.skip(f"skipped: {binary} missing (cargo build --release -p terramesh-cli)")
    csv = tmp_path / "d.csv"
    np.savetxt(csv, np.column_stack([x, y, z]), delimiter=",", header="x,y,z", comments="",
               fmt="%.17g")
    for v, flags in ((py, ["--model", "spherical+exponential", "--lags", "12", "--weights",
                           "pairs"]), (auto, [])):
        out = tmp_path / "v.json"
        p = subprocess.run([binary, "variogram", "--data", str(csv), *flags, "-o", str(out)],
                           capture_output=True, text=True)
        assert p.returncode == 0, p.stderr
        cli, mine = json.loads(out.read_text()), dict(v.fit_info)
        assert Variogram.from_json(out) == v
        for k in ("fit", "candidates", "selection", "experimental"):
            assert mine[k] == cli[k], k
        assert {**mine["lags"], "max_dist": None} == {**cli["lags"], "max_dist": None}


def test_exact_reml_beyond_memory_is_refused_naming_reml_block():
    # In a child process: the memory ceiling is read once per process.
    code = (
        "import numpy as np, terramesh\n"
        "i = np.arange(3000)\n"
        "x, y = (i % 60) * 7.0, (i // 60) * 7.0 + (i % 7) * 0.3\n"
        "z = np.sin(x * 0.01) + y * 0.002\n"
        "for block in (0, 400):\n"
        "    try:\n"
        "        v = terramesh.Variogram.fit(x, y, z, model='exponential', fit='reml',\n"
        "                                    reml_block=block)\n"
        "        print('blocks', v.fit_info['selection']['blocks'])\n"
        "    except terramesh.InputError as e:\n"
        "        print('refused', e)\n"
    )
    env = {**os.environ, "TERRAMESH_MAX_MEMORY": "64M"}
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    lines = p.stdout.splitlines()
    assert len(lines) == 2, p.stdout + p.stderr
    assert lines[0].startswith("refused") and "REML matrix entries" in lines[0], lines[0]
    assert lines[0].endswith("lower reml_block"), lines[0]
    assert lines[1] == "blocks 8"


def test_variogram_json_round_trips_and_reads_build_files(tmp_path):
    v = Variogram(structures=[("spherical", 2.0, 50.0), ("matern", 3.0, 400.0, 0.5)],
                  nugget=0.25, anisotropy_angle=30.0, anisotropy_ratio=0.5)
    text = v.to_json()
    assert json.loads(text)["model"]["anisotropy"] == {"angle": 30.0, "ratio": 0.5}
    assert Variogram.from_json(text) == v
    v.save(tmp_path / "variogram.json")
    assert Variogram.from_json(tmp_path / "variogram.json") == v
    assert Variogram.from_json(v.to_dict()) == v


def test_bad_variograms_and_data_raise_input_errors(field):
    x, y, z = field
    with pytest.raises(terramesh.InputError, match="range"):
        Variogram("spherical", 1.0, -5.0)
    with pytest.raises(terramesh.InputError, match="variogram model"):
        Variogram("cubic", 1.0, 5.0)
    with pytest.raises(terramesh.InputError, match="duplicate|same location"):
        terramesh.krige([0.0, 0.0], [1.0, 1.0], [1.0, 2.0], [0.5], [0.5], variogram=Variogram())
    with pytest.raises(terramesh.InputError, match="z must have"):
        terramesh.krige(x, y, z[:-1], [0.0], [0.0], variogram=Variogram())
    with pytest.raises(terramesh.InputError, match="method"):
        terramesh.krige(x, y, z, [0.0], [0.0], method="nn", variogram=Variogram())


def test_a_bad_json_variogram_is_refused_naming_its_field():
    # A variogram given as JSON (a dict, text or a variogram.json) is the kernel's contract,
    # checked by the kernel's check as the CLI's --variogram FILE.json is (ARCHITECTURE.md,
    # "A given variogram"): each error names the JSON field.
    good = {"nugget": 0.0, "structures": [{"type": "spherical", "psill": 1.0, "range": 5.0}]}
    assert Variogram.from_json(good).structures[0]["range"] == 5.0
    cases = [
        ({"structures": [{"type": "spherical", "psill": 1.0, "range": -5.0}]},
         r"^variogram( file: model)?: structure 1 \(spherical\) range = -5: must be finite and > 0$"),
        ({"nugget": -1.0},
         r"^variogram( file: model)?: nugget = -1: must be finite and >= 0$"),
        ({"structures": [{"type": "spherical", "psill": 1.0, "range": 5.0},
                         {"type": "exponential", "psill": -2.0, "range": 9.0}]},
         r"^variogram( file: model)?: structure 2 \(exponential\) psill = -2: must be finite and >= 0$"),
        ({"anisotropy": {"angle": 30.0, "ratio": 2.0}},
         r"^variogram( file: model)?: anisotropy ratio = 2: must be in \(0, 1\]$"),
    ]
    for change, message in cases:
        bad = {**good, **change}
        for given in (bad, {"model": bad}, json.dumps({"model": bad})):
            with pytest.raises(terramesh.InputError, match=message):
                Variogram.from_json(given)
        with pytest.raises(terramesh.InputError, match=message):
            Variogram(structures=bad.get("structures"), nugget=bad.get("nugget", 0.0),
                      anisotropy_angle=(bad.get("anisotropy") or {}).get("angle"),
                      anisotropy_ratio=(bad.get("anisotropy") or {}).get("ratio"))
        with pytest.raises(terramesh.InputError, match=message):
            terramesh.krige([0.0, 1.0], [0.0, 1.0], [1.0, 2.0], [0.5], [0.5], variogram=bad)


def test_interpolation_keywords_are_checked_once_by_the_librarys_plan_naming_them(field):
    # krige, idw and cross_validate lower their keywords into the plan of `terramesh
    # interpolate` and `terramesh cv`: the same checks, worded with the keywords.
    x, y, z = field
    v = Variogram("exponential", 100.0, 700.0)
    t = ([500.0], [500.0])
    for call in (
        lambda: terramesh.krige(x, y, z, *t, variogram=v, neighbors=0),
        lambda: terramesh.idw(x, y, z, *t, neighbors=0),
        lambda: terramesh.cross_validate(x, y, z, method="ok", variogram=v, neighbors=0),
        lambda: terramesh.cross_validate(x, y, z, method="idw", neighbors=0),
    ):
        with pytest.raises(terramesh.InputError, match=r"^neighbors 0: must be at least 1$"):
            call()
    with pytest.raises(terramesh.InputError, match=r"^IDW takes neighbors or radius, not both$"):
        terramesh.idw(x, y, z, *t, neighbors=4, radius=100.0)
    with pytest.raises(terramesh.InputError, match=r"^power -1: must be a finite number > 0$"):
        terramesh.idw(x, y, z, *t, power=-1.0)
    with pytest.raises(terramesh.InputError, match=r"^radius 0: must be a finite number > 0$"):
        terramesh.cross_validate(x, y, z, method="idw", radius=0.0)
    # Settings the method would ignore are refused, not dropped.
    with pytest.raises(terramesh.InputError, match=r"^drift applies to method uk only$"):
        terramesh.krige(x, y, z, *t, method="ok", drift="quadratic", variogram=v)
    with pytest.raises(terramesh.InputError, match=r"^mean applies to method sk only$"):
        terramesh.krige(x, y, z, *t, method="uk", mean=300.0, variogram=v)
    with pytest.raises(terramesh.InputError,
                       match=r"^radius applies to method idw; kriging takes neighbors$"):
        terramesh.cross_validate(x, y, z, method="ok", variogram=v, radius=100.0)
    with pytest.raises(terramesh.InputError, match=r'^method: unknown interpolation method "nn"'):
        terramesh.cross_validate(x, y, z, method="nn", variogram=v)
    with pytest.raises(terramesh.InputError, match=r"^method 'idw': .*terramesh\.idw"):
        terramesh.krige(x, y, z, *t, method="idw", variogram=v)
    # The default drift with ok (PyKrige's drop-in calls so) and the long names still krige.
    def est(**kw):
        return terramesh.krige(x, y, z, *t, variogram=v, return_variance=False, **kw)[0]

    assert est(method="Ordinary", drift="linear") == est(method="ok")
    assert est(method="simple", mean=300.0) == est(method="sk", mean=300.0) != est(method="sk")
    assert est(method="universal", drift="quadratic") != est(method="uk")
    cv = terramesh.cross_validate(x, y, z, method="IDW", neighbors=8, folds=5)
    assert cv.n == 300 and cv.variance is None
