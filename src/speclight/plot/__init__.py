"""Figures of a speclight dataset (matplotlib, imported lazily by the figure builders).

The names below load :mod:`speclight.plot.figures` on first use (PEP 562), so that a command
that only claims its figure file (``speclight.plot.figure_output``) does not import xarray,
matplotlib and every figure builder at start-up.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from speclight.plot.figures import KINDS, figure_names, plot_dataset, plot_file, plot_files

__all__ = ["KINDS", "figure_names", "plot_dataset", "plot_file", "plot_files"]


def __getattr__(name: str) -> Any:
    if name in __all__:
        return getattr(import_module("speclight.plot.figures"), name)
    raise AttributeError(f"module 'speclight.plot' has no attribute {name!r}")
