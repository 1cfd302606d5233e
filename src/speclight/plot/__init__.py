"""Figures of a speclight dataset (matplotlib, imported lazily by the figure builders)."""

from speclight.plot.figures import KINDS, figure_names, plot_dataset, plot_file, plot_files

__all__ = ["KINDS", "figure_names", "plot_dataset", "plot_file", "plot_files"]
