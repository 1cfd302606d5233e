"""Everything runs offline (issue 9, "what held and must keep holding"): a run that would
reach for the network (an IERS table, an ephemeris, a filter curve, a font) fails here.

The child process replaces every way Python opens a network connection with one that
raises, before speclight is imported, then simulates two built-in scenarios on a few epochs
(TLE + Earth orientation + DE421 ephemeris, SPECTRL2, speclite-free bands, lasers), writes
the NetCDF file and draws the overview figure.
"""

import subprocess
import sys
import textwrap

CHILD = textwrap.dedent(
    """
    import socket

    def refuse(*args, **kwargs):
        raise OSError("network access attempted: " + repr(args[:2]))

    socket.socket.connect = refuse
    socket.socket.connect_ex = refuse
    socket.create_connection = refuse
    socket.getaddrinfo = refuse

    import sys
    from pathlib import Path

    import yaml

    from speclight.io.netcdf import write_dataset
    from speclight.plot import plot_files
    from speclight.scenario import example_text, parse_scenario
    from speclight.simulation import simulate

    out = Path(sys.argv[1])
    windows = {"calsphere": "2020-02-29T21:16:04Z", "box-wing-laser": "2019-08-30T02:20:02Z"}
    for name, stop in windows.items():
        d = yaml.safe_load(example_text(name))
        d["time"]["stop"] = stop
        d["time"]["start"] = stop[:-3] + "00Z"
        d["render"]["resolution_px"] = 32
        result = simulate(parse_scenario(yaml.safe_dump(d), source=name))
        write_dataset(result.dataset, out / f"{name}.nc")
    plot_files(out / "calsphere.nc", out / "calsphere.png")
    print("offline ok")
    """
)


def test_a_run_needs_no_network(tmp_path):
    run = subprocess.run(
        [sys.executable, "-c", CHILD, str(tmp_path)], capture_output=True, text=True, timeout=300
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert "offline ok" in run.stdout
    assert (tmp_path / "calsphere.png").exists() and (tmp_path / "box-wing-laser.nc").exists()
