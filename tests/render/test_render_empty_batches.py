"""A batch of epochs in which no pixel is both lit and seen renders zero, and the run goes on.

Reproducers ../shared/repro/plate-crash (issue 9): a plate seen edge-on or from its unlit
side made Mitsuba's ray caster abort the whole process (SIGABRT in Dr.Jit, ``jit_var(r0):
unknown variable!``) when it was handed zero shadow rays. The render runs in a child process
here, so that a crash fails the test instead of killing the test runner.
"""

import subprocess
import sys
import textwrap

import pytest

from speclight.render import available_variants

RGB = [v for v in available_variants() if v.startswith(("llvm_", "cuda_")) and v.endswith("_rgb")]

CODE = textwrap.dedent(
    """
    import numpy as np
    from speclight.render import render_intensity
    from speclight.render.laser_returns import LaserLight, render_laser_returns
    from speclight.target import Material, Reflectance, plate

    grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    target = plate(1.0, 1.0, grey)  # in the body x-y plane, normal +z, two-sided
    # Sun below the plate, observer above: every seen pixel is unlit (zero shadow rays)
    sun = np.array([[0.0, 0.3, -1.0], [0.0, 0.0, -1.0]])
    obs = np.array([[0.0, 0.0, 1.0], [0.3, 0.0, 1.0]])
    wl = np.array([500.0, 600.0])
    res = render_intensity(target, sun, obs, np.ones((2, 2)), wl, resolution_px=32,
                           variant="{variant}")
    assert np.all(res.intensity_W_sr_nm == 0.0), res.intensity_W_sr_nm
    # edge-on: no pixel sees the plate at all (zero primary hits)
    edge = render_intensity(target, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]], np.ones((1, 2)), wl,
                            resolution_px=32, variant="{variant}")
    assert np.all(edge.intensity_W_sr_nm == 0.0)
    # a bistatic laser on the unlit side: zero shadow rays in the laser render too
    light = LaserLight(sun[:1], np.array([0]), np.ones((1, 1)))
    rr = render_laser_returns(target, obs[:1], [light], wl, resolution_px=32, variant="{variant}")
    assert np.all(rr.intensity_W_sr_nm(0) == 0.0)
    print("ok")
    """
)


@pytest.mark.skipif(not RGB, reason="needs a vectorised Mitsuba variant (the crash was in Dr.Jit)")
def test_unlit_and_edge_on_plates_render_zero_without_crashing():
    out = subprocess.run(
        [sys.executable, "-c", CODE.format(variant=RGB[0])],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().endswith("ok")


def test_numpy_caster_renders_unlit_plates_as_zero():
    exec(CODE.format(variant="numpy"), {})
