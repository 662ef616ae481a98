"""Runs PyKrige's own tests of its 2D classes against terramesh.pykrige.

Everything PyKrige's test file imports comes from the installed PyKrige (``core``,
``kriging_tools``, ``variogram_models``, the 3D classes) except ``pykrige.ok`` and
``pykrige.uk``, which are aliased to terramesh's drop-ins, so that every test of
``OrdinaryKriging`` and ``UniversalKriging`` runs terramesh's code.
"""

import sys

import pykrige  # the real package: core, kriging_tools, variogram_models, ok3d, uk3d

import terramesh.pykrige.ok
import terramesh.pykrige.uk

sys.modules["pykrige.ok"] = terramesh.pykrige.ok
sys.modules["pykrige.uk"] = terramesh.pykrige.uk
pykrige.ok = terramesh.pykrige.ok
pykrige.uk = terramesh.pykrige.uk


def pytest_report_header(config):
    return [
        f"pykrige.ok -> {sys.modules['pykrige.ok'].__file__}",
        f"pykrige.uk -> {sys.modules['pykrige.uk'].__file__}",
    ]
