"""The command line says its flags where the plain-array cores name their Python parameters
(docs/design.md: "the core does not speak the CLI"; STYLE.md item 16).

References: the flags of each command's ``--help``, written out by hand; the cores' messages
as a Python caller sees them.
"""

from __future__ import annotations

import pytest

from speclight.cli import cli_words
from speclight.errors import InputError
from speclight.estimate.inputs.measured import read_measured
from speclight.estimate.spectra.unmix_run import check_unmix_options
from speclight.estimate.spin_axis.spin_axis_core import check_search_options
from speclight.maps.writer import check_map_options

FLAGS = {
    "n": "--n",
    "extract": "--extract",
    "endmembers": "--endmembers",
    "loaded": "--scenario",
    "force": "--force",
    "bin_s": "--bin-s",
    "draws": "--draws",
    "method": "--method",
}


@pytest.mark.parametrize(
    ("python", "command_line"),
    [
        ("bin_s = -1.0 must be a duration > 0 s", "--bin-s = -1.0 must be a duration > 0 s"),
        ("draws = 0 must be 1..10000 (draws of the bootstrap)",
         "--draws = 0 must be 1..10000 (draws of the bootstrap)"),
        ("extract='atgp' needs n=K (the number of endmembers)",
         "--extract atgp needs --n K (the number of endmembers)"),
        ("endmembers=['scenario'] needs loaded=SCENARIO",
         "--endmembers scenario needs --scenario SCENARIO"),
        ("give endmembers=[a.csv, b.csv] or extract=pca",
         "give --endmembers a.csv b.csv or --extract pca"),
        ("`n` is the number of endmembers to extract; use it with `extract`",
         "--n is the number of endmembers to extract; use it with --extract"),
        ("choose another name or pass force=True to replace it",
         "choose another name or pass --force to replace it"),
        ("method='gradient': no derivative (use method='slsqp')",
         "--method gradient: no derivative (use --method slsqp)"),
        # plain words in prose stay: "the number of endmembers", "nside^2", "render.method"
        ("2 endmembers in render.method, nside^2 pixels",
         "2 endmembers in render.method, nside^2 pixels"),
    ],
)  # fmt: skip
def test_messages_in_the_command_line_s_words(python, command_line):
    assert cli_words(python, FLAGS) == command_line


@pytest.mark.parametrize(
    ("call", "start"),
    [
        (lambda: check_search_options(grid_deg=0, n_phases=72), "grid_deg: grid_deg = 0"),
        (lambda: check_search_options(grid_deg=2.0, n_phases=0), "n_phases: n_phases = 0"),
        (lambda: read_measured("x.csv", source="moon"), "source: source = 'moon'"),
        (lambda: check_map_options(directions=5, phase_angles_deg=[0.0], rolls=8, chunk=512),
         "directions: directions = 5"),
        (lambda: check_map_options(directions=12, phase_angles_deg=[0.0], rolls=0, chunk=512),
         "rolls: rolls = 0"),
        (lambda: check_unmix_options(endmembers=None, extract="atgp", n=None, method="nnls"),
         "n: extract='atgp' needs n=K"),
    ],
)  # fmt: skip
def test_python_callers_read_their_parameter_names(call, start):
    with pytest.raises(InputError) as err:
        call()
    assert str(err.value).startswith(start), str(err.value)
    assert "--" not in str(err.value)
