"""Shape and rotation-state inversion of light curves (``speclight shape``; docs/shape.md).

Plain-array cores beside the run, as in the other estimate products:

* :mod:`.damit_lc`: DAMIT's ``.lc`` files in and out; :mod:`.shape_inputs`: those or
  speclight's light curves with their scenario's geometry, as :mod:`.inversion_data`;
* :mod:`.egi` (facet normals on a HEALPix sphere, areas), :mod:`.scattering` (Lambert,
  Lommel-Seeliger, speclight's materials), :mod:`.convex_model` (the light curve of a convex
  polyhedron with analytic derivatives), :mod:`.lm_solver`, :mod:`.convex_fit`;
* :mod:`.period_scan`, :mod:`.pole_search`, :mod:`.uncertainty`, :mod:`.minkowski` (the
  polyhedron of an EGI, OBJ), :mod:`.facet_spectra` (per-band facet factors);
* :mod:`.two_frequencies`: torque-free states fitted through speclight's propagation, families;
* :mod:`.shape_run` (files to a result) and :mod:`.shape_dataset` (SHAPE.nc).
"""

from speclight.estimate.shape.damit_lc import DamitLightCurve, read_damit_lc, write_damit_lc
from speclight.estimate.shape.shape_inputs import read_shape_input
from speclight.estimate.shape.shape_run import ShapeOptions, ShapeRun, run_shape

__all__ = [
    "DamitLightCurve",
    "ShapeOptions",
    "ShapeRun",
    "read_damit_lc",
    "read_shape_input",
    "run_shape",
    "write_damit_lc",
]
