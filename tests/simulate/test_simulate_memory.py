"""Up-front run limits (speclight.simulation.memory): a run that cannot fit in memory, or whose
path-mode render would take days, is refused before any work with the estimate and the fields
to reduce (issue 9, item 5). Reproducers: /work/shared/repro/fuzz/NNNN-*."""

from __future__ import annotations

import time
from datetime import timedelta
from typing import Any

import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import LoadedScenario, example_text, parse_scenario
from speclight.simulation import memory
from speclight.simulation.pipeline import simulate

GIB = 1024**3


def _loaded(name: str = "calsphere", **edits: Any) -> LoadedScenario:
    d = yaml.safe_load(example_text(name))
    if edits.pop("no_target", False):
        d.pop("target")
    if "window_s" in edits:
        d["time"]["stop"] = d["time"]["start"] + timedelta(seconds=edits.pop("window_s"))
    for path, value in edits.items():
        section, key = path.split("__")
        d[section][key] = value
    return parse_scenario(yaml.safe_dump(d), source="test.yaml")


def test_epoch_count_is_the_time_grids() -> None:
    from speclight.simulation.geometry_stage import time_grid

    loaded = _loaded(time__step_s=0.7)
    assert memory.grid_epochs(loaded.scenario) == time_grid(loaded.scenario.time).size


def test_geometry_only_runs_cost_no_spectra_and_are_refused_above_the_limit() -> None:
    # fuzz/0017, 0019: 2e6 and 9.9e6 epochs without a target passed the 1e7 epoch limit and
    # died with MemoryError allocating the (N, 189) solar irradiance; geometry-only runs now
    # allocate nothing per wavelength bin
    loaded = _loaded(no_target=True, window_s=2_000_000, time__step_s=1.0)
    n = memory.grid_epochs(loaded.scenario)
    est = memory.estimate_memory(loaded.scenario, n)
    assert est.parts["epochs"] == n * memory.BYTES_PER_EPOCH
    assert "spectra" not in est.parts
    # measured: this run (2,000,001 epochs, calsphere without target) peaked at 3028 MiB RSS
    # with its in-memory file, pointing variables included (BENCHMARKS.md, Memory); the
    # linear model is within 10 %
    assert abs(est.total_bytes / (3028 * 1024**2) - 1) < 0.10
    memory.check_run_limits(loaded, n, limit_bytes=8 * GIB)  # fits
    with pytest.raises(InputError) as err:
        memory.check_run_limits(loaded, n, limit_bytes=2 * GIB)
    msg = str(err.value)
    assert msg.startswith("test.yaml: time: this run needs about 3.")
    assert "2000001 epochs" in msg
    assert "more than the limit of 2 GiB" in msg and "reduce time" in msg


def test_a_run_that_fits_passes() -> None:
    loaded = _loaded()
    memory.check_run_limits(loaded, memory.grid_epochs(loaded.scenario), limit_bytes=2 * GIB)


def test_resolution_8192_is_refused_for_its_render_batch() -> None:
    # fuzz/0282: one 8192 px epoch is 67 million primary rays in one batch (~23 GB)
    loaded = _loaded(render__resolution_px=8192)
    est = memory.estimate_memory(loaded.scenario, 481)
    assert est.parts["render batch"] == 8192**2 * memory.BYTES_PER_RAY
    with pytest.raises(InputError, match=r"render\.resolution_px"):
        memory.check_run_limits(loaded, 481, limit_bytes=16 * GIB)


def test_billion_wavelength_bins_are_refused_before_any_work() -> None:
    # fuzz/0298: spectrum.step_nm 1e-6 (9.4e8 bins) died allocating the wavelength grid
    loaded = _loaded(spectrum__step_nm=1e-6)
    t0 = time.perf_counter()
    with pytest.raises(InputError, match=r"940000001 bins.*spectrum\.step_nm"):
        simulate(loaded)  # the default limit: no machine has the ~0.5 TB this needs
    assert time.perf_counter() - t0 < 1.0


def test_day_long_path_render_is_refused_with_its_estimate() -> None:
    # 256 px x 65536 spp x 481 epochs: 481 x (0.02 s + 256^2 x 65536 / 1e7 s) = 2.07e5 s,
    # about 57.4 h (the model of speclight.simulation.memory.path_render_seconds)
    loaded = _loaded(render__mode="path", render__samples_per_pixel=65536)
    with pytest.raises(InputError) as err:
        simulate(loaded)
    msg = str(err.value)
    assert "render.samples_per_pixel: path mode at 256 px x 65536 spp x 481 epochs" in msg
    assert "about 57.4 h" in msg and "at most 24 h per run" in msg


def test_path_render_note_states_the_up_front_estimate() -> None:
    # 481 epochs x (0.02 s + 128^2 x 16 / 1e7 s) = 22.2 s; at 256 spp 481 x 0.439 s = 3.5 min
    loaded = _loaded(render__mode="path", render__resolution_px=128)
    note = memory.path_render_note(loaded.scenario, 481)
    assert note == "path mode: 481 epochs x 128 px x 16 spp, about 22 s to render"
    loaded = _loaded(render__mode="path", render__resolution_px=128, render__samples_per_pixel=256)
    assert memory.path_render_note(loaded.scenario, 481).endswith("about 3.5 min to render")


def test_million_spp_is_refused_at_load_with_its_estimate() -> None:
    # fuzz/0285-path-mode-1e6-spp: ran until killed
    with pytest.raises(InputError) as err:
        _loaded(render__mode="path", render__resolution_px=32, render__samples_per_pixel=10**6)
    msg = str(err.value)
    # 0.02 s + 32^2 x 1e6 / 1e7 samples/s = 102 s per epoch
    assert "samples_per_pixel = 1000000 would take about 102 s per epoch at 32 px" in msg
    assert "at most 65536" in msg


def test_default_limit_is_a_fraction_of_physical_memory() -> None:
    import os

    physical = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    assert 0 < memory.memory_limit_bytes() <= memory.MEMORY_FRACTION * physical


@pytest.mark.parametrize("name", ["box-wing", "calsphere", "cube-materials", "starlink-v1.5"])
def test_channel_count_is_the_renderers_layout(name: str) -> None:
    # issue 22 item 8: the (epochs x channels) weight array was not in the model; its channel
    # count must be the one the single-mode renderer lays out (3,271 for the box-wing's three
    # plastics: 4 materials + 3 x 33^2 diffuse nodes)
    from speclight.render.material_channels import ChannelLayout
    from speclight.simulation.reflection import build_target

    loaded = _loaded(name)
    layout = ChannelLayout(build_target(loaded))
    assert memory.channel_count(loaded.scenario, loaded.resolve) == layout.n_channels


def test_plastic_targets_count_the_channel_weights_the_render_allocates() -> None:
    # What the single-mode render allocates, traced (numpy reports its arrays to tracemalloc):
    # the box-wing (3 plastics, 3,271 channels) at 8 px over 2000 epochs. The model's render
    # terms (rays of a batch, channel weights, spectra) must bound the traced peak; without
    # the channel term they do not (699 MiB estimated, 879 MiB measured at 10k epochs).
    import tracemalloc

    import numpy as np

    from speclight.render.raycast import NumpyCaster
    from speclight.render.single import render_single_polarized
    from speclight.simulation.radiometry import wavelength_grid_nm
    from speclight.simulation.reflection import build_target

    loaded = _loaded("box-wing", render__resolution_px=8)
    target = build_target(loaded)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    n = 2000
    rng = np.random.default_rng(1)
    sun, obs = (v / np.linalg.norm(v, axis=1)[:, None] for v in rng.normal(size=(2, n, 3)))
    caster = NumpyCaster(target)
    tracemalloc.start()
    try:
        irradiance = np.ones((n, wl.size))
        render_single_polarized(target, sun, obs, irradiance, wl, caster, 8, polarization=False)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    est = memory.estimate_memory(loaded.scenario, n, loaded.resolve)
    weights = n * 3271 * 8  # w (N, C) float64 alone
    assert est.parts["channels"] >= weights
    render = est.parts["render batch"] + est.parts["spectra"]
    assert render < peak <= render + est.parts["channels"]
