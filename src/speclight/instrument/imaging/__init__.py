"""Detector frames: what the telescope's camera records (docs/frames.md).

The instrument's imaging product, beside its light curves: the target's flux per band from
the pipeline, spread along its path on the detector during each exposure and blurred by the
PSF (GalSim), a resolved image where the target is large against the PSF (the kept
renders), Hipparcos stars, the sky's brightness (Krisciunas & Schaefer 1991 with twilight),
Poisson and read noise, dark current, gain, bias and saturation; FITS frames with their WCS
and truth. ``speclight frames OUT.nc -o DIR/`` runs it (:func:`make_frame_files`).

Plain-array cores, each testable alone: :mod:`.psf` (GalSim profiles and fine-grid kernels),
:mod:`.streak_raster` (a path of points onto pixels), :mod:`.sky_projection` (TAN and the
WCS), :mod:`.detector_readout` (noise and ADC), :mod:`.sky_brightness`,
:mod:`.star_catalogue`, :mod:`.star_photometry`, :mod:`.target_path`; composed by
:mod:`.exposure` (one frame) and :mod:`.frame_set` (all frames of a dataset).
"""

from speclight.instrument.imaging.frames_run import FramesResult, make_frame_files, read_imaging

__all__ = ["FramesResult", "make_frame_files", "read_imaging"]
