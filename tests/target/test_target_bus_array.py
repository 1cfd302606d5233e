"""bus_array's array_offset_m: the array hinged on the bus's top edge (an L, the starlink-v1.5
example's shape), its plane, areas and normal; a bad offset names the field."""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.target import Material, Reflectance
from speclight.target.shapes import bus_array

WHITE = Material("w", "lambertian", Reflectance.constant(1.0))


def test_an_offset_array_stands_on_the_bus_edge():
    bus = (1.3, 2.8, 0.3)
    target = bus_array(WHITE, bus, (2.8, 8.1), array_gap_m=0.0, array_offset_m=-0.65)
    parts = {p.name: p for p in target.parts}
    array = parts["array"].vertices_m
    # the plane x = -0.65 (the bus's -x face), from the bus top (z = -0.15) 8.1 m up
    np.testing.assert_array_equal(array[:, 0], -0.65)
    assert array[:, 2].max() == pytest.approx(-0.15) and array[:, 2].min() == pytest.approx(-8.25)
    # its foot is the bus's top -x edge: every bus vertex lies on the array's +x side
    assert parts["bus"].vertices_m[:, 0].min() == pytest.approx(-0.65)
    t = array[parts["array"].faces[0]]
    n = np.cross(t[1] - t[0], t[2] - t[0])
    np.testing.assert_allclose(n / np.linalg.norm(n), [1.0, 0.0, 0.0], atol=1e-15)
    # Fankhauser et al. 2023's areas: chassis underside 3.64 m2, array 22.68 m2
    assert parts["bus_nadir"].area_m2 == pytest.approx(1.3 * 2.8)
    assert parts["array"].area_m2 == pytest.approx(2.8 * 8.1)


def test_the_default_array_is_centred_as_before():
    array = next(p for p in bus_array(WHITE).parts if p.name == "array").vertices_m
    np.testing.assert_array_equal(array[:, 0], 0.0)


@pytest.mark.parametrize("offset", [float("nan"), float("inf")])
def test_a_bad_offset_names_the_field(offset):
    with pytest.raises(InputError, match="array_offset_m") as err:
        bus_array(WHITE, array_offset_m=offset)
    assert err.value.field == "shape.array_offset_m"
