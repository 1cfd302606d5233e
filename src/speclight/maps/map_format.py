"""The reflectivity map's store format, shared by its writer and its readers.

Layout (Zarr format 3, a folder ``MAP.zarr``):

* ``intensity(direction, phase, roll, wavelength)`` float32 [W sr-1 nm-1]: the target's
  radiant intensity under the Sun at 1 AU (bin-averaged spectrum of
  :func:`speclight.illumination.solar_irradiance_W_m2_nm`), no Earth shadow;
* ``count_rate(direction, phase, roll, band)`` float32 [s-1]: photo-electrons per second
  for a range of 1 m, an aperture of 1 m^2, no atmosphere (transmission 1), the scenario's
  optics, QE and bands;
* ``range_offset(direction, wavelength)`` float32 [m], only for a scenario with lasers and
  phase angle 0 among the map's: a coaxial laser's mean one-way range offset from the
  centre of mass per wavelength bin (single scattering);
* ``range_histogram(direction, band, range_bin)`` float32 [s-1 per bin], with ``range_offset``
  where the scenario has bands: photo-electrons per second per range bin of a coaxial laser
  of spectral irradiance 1 W m-2 nm-1 on every wavelength bin, range 1 m, aperture 1 m^2,
  no atmosphere (the ``count_rate`` conditions), single scattering; ``range_bin(range_bin)``
  (bin centres) and ``range_bin_bounds(range_bin, nv)`` [m] as in the ``simulate`` output
  (:func:`speclight.ranging.bins.range_bin_edges_m`, single-bounce span);
* ``direction_body(direction, xyz)``, ``phase_angle_deg(phase)``, ``roll_deg(roll)``,
  ``wavelength(wavelength)`` [nm];
* ``chunk_state(chunk)`` uint8: 0 to do, 1 done, 2 failed (each written after its chunk's
  data, so a killed run loses only the chunks in flight);
* attributes: ``parameters`` (what a resumed run must match), band names, units, the
  scenario YAML, target and materials, engine and speclight versions, render variant,
  ``failed_chunks`` (chunk -> message) and ``complete``.

Each array carries its dimension names (:data:`DIMS`), so that ``xarray.open_zarr(path,
consolidated=False)`` reads the store too. The store is written in place, not to a
temporary name: its partial content is the resume state (:mod:`speclight.maps.writer.map_store`).
Readers (:mod:`speclight.maps.map_lookup`: ``render.mode: map``, ``speclight spin-axis``)
accept only a store whose ``complete`` is true.
"""

#: The ``format`` attribute of every map store (a folder that lacks it is not a map).
FORMAT_NAME = "speclight reflectivity map"
#: The per-direction arrays a chunk writes.
DATA_ARRAYS = ("intensity", "count_rate", "range_offset", "range_histogram")
#: Dimension names of each array (Zarr ``dimension_names``: ``xarray.open_zarr`` reads them).
DIMS = {
    "intensity": ("direction", "phase", "roll", "wavelength"),
    "count_rate": ("direction", "phase", "roll", "band"),
    "range_offset": ("direction", "wavelength"),
    "range_histogram": ("direction", "band", "range_bin"),
    "chunk_state": ("chunk",),
    "direction_body": ("direction", "xyz"),
    "phase_angle_deg": ("phase",),
    "roll_deg": ("roll",),
    "wavelength": ("wavelength",),
    "range_bin": ("range_bin",),
    "range_bin_bounds": ("range_bin", "nv"),
}
