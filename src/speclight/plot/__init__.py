"""Figures of a speclight dataset (matplotlib, imported lazily)."""

from speclight.plot.figures import plot_dataset, plot_file

__all__ = ["plot_dataset", "plot_file"]
