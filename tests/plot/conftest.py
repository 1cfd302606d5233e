"""Fixtures: synthetic dataset files for the plot tests."""

from __future__ import annotations

from pathlib import Path

import pytest
from plot_datasets import full_dataset, geometry_dataset, image_dataset, write


@pytest.fixture
def geometry_file(tmp_path: Path) -> Path:
    return write(geometry_dataset(), tmp_path / "geometry.nc")


@pytest.fixture
def full_file(tmp_path: Path) -> Path:
    return write(full_dataset(), tmp_path / "full.nc")


@pytest.fixture
def image_file(tmp_path: Path) -> Path:
    return write(image_dataset(), tmp_path / "images.nc")
