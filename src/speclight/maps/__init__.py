"""Reflectivity maps: the target rendered once for many body-frame geometries, then read back
by interpolation instead of a render (docs/reflectivity-map.md). Forward modelling, used by
``render.mode: map`` and by the spin-axis search.

* :mod:`.map_format`: the store's layout and format name, shared by writer and readers;
* :mod:`.map_geometry`: the conventions (HEALPix phase-vector directions, phase angle, roll);
* :mod:`.map_lookup`: a complete map read and interpolated (numpy and astropy-healpix only);
  :mod:`.map_lookup_grad` its derivatives with respect to the body-frame directions;
* :mod:`speclight.maps.writer`: ``speclight reflectivity-map``, the map rendered (through
  :mod:`speclight.render`'s public functions) chunk by chunk into a resumable store. It
  stands above ``simulate`` and ``scenario``, which read maps: this package does not import
  it.
"""

from speclight.maps.map_format import FORMAT_NAME
from speclight.maps.map_lookup import MapHeader, ReflectivityMap, load_map, read_header

__all__ = ["FORMAT_NAME", "MapHeader", "ReflectivityMap", "load_map", "read_header"]
