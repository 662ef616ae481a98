"""Drop-ins for PyKrige 1.7's 2D kriging classes, computed by terramesh.

Change one import line::

    from terramesh.pykrige.ok import OrdinaryKriging      # was: from pykrige.ok import ...
    from terramesh.pykrige.uk import UniversalKriging     # was: from pykrige.uk import ...

The constructors take PyKrige's arguments and the objects offer its methods and attributes.
The terramesh kernel computes built-in models in Euclidean coordinates with no drift or a
``regional_linear`` one; the other options run the same kriging system in numpy
(:mod:`terramesh.pykrige._base`). ``python/CONFORMANCE.md`` lists how PyKrige's own test
suite fares.
"""

from . import ok, uk, variogram_models

__all__ = ["ok", "uk", "variogram_models"]
