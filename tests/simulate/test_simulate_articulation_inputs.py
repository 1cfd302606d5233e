"""Scenario inputs of target.articulation: bad values are refused with the field named,
and a tabulated angle reaches the render (a plate turned edge-on goes dark)."""

import numpy as np
import pytest
import yaml

import speclight
from speclight.errors import InputError

#: The array turned toward the Sun about the nadir axis through its centre (the starlink-v1.5
#: example before issue 24, whose bus now yaws instead): the array centred above the bus.
SUN_TRACKING = {"axis": [0, 0, 1], "hinge_point_m": [0, 0, -1.75], "normal": [1, 0, 0]}


def _starlink(articulation):
    d = yaml.safe_load(speclight.scenario.example_text("starlink-v1.5"))
    d["attitude"] = {"model": "nadir"}
    d["target"]["shape"] = {"builtin": "bus_array"}
    d["target"]["articulation"] = articulation
    d["illumination"] = {"sun": True}
    return d


@pytest.mark.parametrize(
    "joint, match",
    [
        ({"axis": [0, 0, 0], "normal": [1, 0, 0]}, "axis"),
        ({"axis": [0, 0, 1], "normal": [0, 0, 2]}, "not parallel"),
        ({"axis": [0, 0, 1], "normal": [1, 0, 0], "mode": "table"}, "table_file"),
        ({"axis": [0, 0, 1], "normal": [1, 0, 0], "mode": "spin"}, "sun_tracking"),
        ({"axis": [0, 0, 1], "normal": [1, 0, 0], "hinge": [0, 0, 0]}, "hinge"),
    ],
)
def test_bad_joints_are_refused_when_loading(joint, match):
    with pytest.raises(InputError, match=match) as err:
        speclight.load(_starlink({"array": joint}))
    assert "articulation" in str(err.value)


def test_a_joint_on_a_missing_part_names_the_parts():
    loaded = speclight.load(_starlink({"wing": {"axis": [0, 0, 1], "normal": [1, 0, 0]}}))
    short = {"time.stop": "2024-03-20T23:59:00Z", "time.start": "2024-03-20T23:58:40Z"}
    with pytest.raises(InputError, match=r"'wing' is not a part.*bus_nadir, bus, array"):
        speclight.simulate(loaded, {**short, "render.resolution_px": 16})


def test_tabulated_angle_turns_the_array(tmp_path):
    # The array (normal +x at angle 0) held at 0 and at 90 deg about z by a table: the two
    # runs differ, and the sun-tracking run equals the table run whose angle is the tracking
    # angle (atan2(s_y, s_x) for axis z and normal +x) at that epoch.
    t0 = "2024-03-20T23:59:30Z"
    over = {"time.start": t0, "time.stop": t0, "render.resolution_px": 32}
    track = speclight.simulate(_starlink({"array": SUN_TRACKING}), over)
    s = track.geometry.sun_direction_body[0]
    angle = float(np.degrees(np.arctan2(s[1], s[0])))
    f = tmp_path / "angles.csv"
    f.write_text(
        f"time_utc,angle_deg\n2024-03-20T23:00:00Z,{angle}\n2024-03-21T01:00:00Z,{angle}\n"
    )
    joint = {"axis": [0, 0, 1], "hinge_point_m": [0, 0, -1.75], "normal": [1, 0, 0],
             "mode": "table", "table_file": str(f)}  # fmt: skip
    table = speclight.simulate(_starlink({"array": joint}), over)
    i_track = track.dataset["intensity"].values
    i_table = table.dataset["intensity"].values
    np.testing.assert_allclose(i_table, i_track, rtol=1e-9)
    joint["table_file"] = str(tmp_path / "zero.csv")
    (tmp_path / "zero.csv").write_text(
        "time_utc,angle_deg\n2024-03-20T23:00:00Z,0\n2024-03-21T01:00:00Z,0\n"
    )
    zero = speclight.simulate(_starlink({"array": joint}), over)
    assert not np.allclose(zero.dataset["intensity"].values, i_track, rtol=1e-3)
