"""docs/api.md runs as written: its Python blocks in order, in one session, in an empty
folder (the page's own assertions check the physics it states)."""

import os
import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "api.md"


def test_api_page_runs_as_written(tmp_path, capsys):
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), flags=re.S)
    assert len(blocks) >= 5
    namespace: dict = {"__name__": "__docs__"}
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        for code in blocks:
            exec(compile(code, str(DOC), "exec"), namespace)  # our own page
    finally:
        os.chdir(cwd)
    out = capsys.readouterr().out
    assert "Input should be greater than 0" in out
    assert (tmp_path / "box-wing-magnitudes.png").stat().st_size > 0
    assert abs(namespace["period"].period_s / 120.0 - 1) < 0.01  # the example's spin


def test_api_page_lists_every_estimate_function():
    import speclight.estimate as estimate

    text = DOC.read_text()
    functions = [n for n in estimate.__all__ if callable(getattr(estimate, n)) and n[0].islower()]
    listed = {n for n in functions if f"{n}(" in text}
    # the page documents the commands' entry points; helpers of one command are on its page
    for name in (
        "read_measured",
        "fit_scenario",
        "upsample",
        "unmix",
        "reflection_map",
        "estimate_period",
        "spin_axis_search",
    ):
        assert name in listed, name


def test_api_page_lists_the_map_functions():
    import speclight.maps as maps
    import speclight.maps.writer as writer

    text = DOC.read_text()
    for name in ("load_map", "read_header"):
        assert f"speclight.maps.{name}(" in text and callable(getattr(maps, name)), name
    assert "speclight.maps.writer.reflectivity_map(" in text and callable(writer.reflectivity_map)
