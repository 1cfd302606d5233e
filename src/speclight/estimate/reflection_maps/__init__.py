"""Reflection maps: band reflectance factors on a HEALPix sphere in the body frame
(``speclight reflection-map``, docs/reflection-map.md).

* :mod:`.reflection_map_run`: the command's run (:func:`reflection_map_measured`);
* :mod:`.reflection_map_core`: the plain-array core (:func:`reflection_map`).

(The reflectivity map, the target rendered over body-frame geometries, is forward
modelling: :mod:`speclight.maps`.)
"""

from speclight.estimate.reflection_maps.reflection_map_core import ReflectionMap, reflection_map
from speclight.estimate.reflection_maps.reflection_map_run import reflection_map_measured

__all__ = ["ReflectionMap", "reflection_map", "reflection_map_measured"]
