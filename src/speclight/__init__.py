"""speclight: spectral light curves of satellites and space debris.

Simulates what a ground telescope measures from an orbiting target, wavelength by
wavelength, and inverts such measurements. See ``speclight --help`` and ``docs/``.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("speclight")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
