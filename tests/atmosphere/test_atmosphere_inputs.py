"""Bad atmosphere inputs: names, parameters, ranges, 6S unavailable."""

from __future__ import annotations

import numpy as np
import pytest

import speclight.atmosphere.sixs as sixs
from speclight.atmosphere import SixSUnavailable, transmission
from speclight.errors import InputError

WL = np.arange(400.0, 701.0, 5.0)


def test_unknown_model_suggests_the_right_one() -> None:
    with pytest.raises(InputError, match="did you mean 'spectrl2'"):
        transmission("spectral2", WL, [45.0], 0.0)  # type: ignore[arg-type]


def test_unknown_and_misplaced_parameters_are_named() -> None:
    with pytest.raises(InputError, match="did you mean 'water_vapour_cm'") as err:
        transmission("spectrl2", WL, [45.0], 0.0, water_vapor_cm=1.0)
    assert err.value.field == "atmosphere.water_vapor_cm"
    with pytest.raises(InputError, match="applies only to model 6s"):
        transmission("spectrl2", WL, [45.0], 0.0, aerosol_profile="maritime")
    with pytest.raises(InputError, match="did you mean 'maritime'"):
        transmission("6s", WL, [45.0], 0.0, aerosol_profile="maritim")


@pytest.mark.parametrize(
    ("key", "value"), [("water_vapour_cm", -1.0), ("ozone_atm_cm", 5.0), ("aod_500nm", "x")]
)
def test_out_of_range_values_name_the_field(key: str, value: object) -> None:
    with pytest.raises(InputError, match=f"{key} = .* must be a number") as err:
        transmission("spectrl2", WL, [45.0], 0.0, **{key: value})
    assert err.value.field == f"atmosphere.{key}"


def test_none_is_one_above_horizon_and_nan_below() -> None:
    t = transmission("none", WL, [10.0, -10.0], 0.0)
    assert np.all(t[0] == 1.0) and np.isnan(t[1]).all()


def test_spectrl2_refuses_grid_outside_its_range() -> None:
    with pytest.raises(InputError, match="SPECTRL2's range"):
        transmission("spectrl2", np.arange(250.0, 500.0, 5.0), [45.0], 0.0)


def test_missing_6s_is_an_input_error_or_falls_back_when_allowed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def broken() -> None:
        raise SixSUnavailable("libgfortran.so.5: cannot open shared object file")

    monkeypatch.setattr(sixs, "sixs_executable", broken)
    monkeypatch.setenv("SPECLIGHT_CACHE_DIR", "/nonexistent-speclight-cache")
    with pytest.raises(InputError, match=r"libgfortran.*fallback_to_spectrl2") as err:
        transmission("6s", WL, [45.0], 0.0)
    assert err.value.field == "atmosphere.model"
    with pytest.warns(UserWarning, match="using SPECTRL2"):
        t = transmission("6s", WL, [45.0], 0.0, fallback_to_spectrl2=True)
    assert np.allclose(t, transmission("spectrl2", WL, [45.0], 0.0))


def test_sixs_profile_names_accept_py6s_spelling_and_warn_on_ignored_columns() -> None:
    from speclight.atmosphere.params import parse_params

    p = parse_params(
        "6s", {"atmosphere_profile": "MidlatitudeSummer", "aerosol_profile": "NoAerosols"}
    )
    assert (p.atmosphere_profile, p.aerosol_profile) == ("midlatitude-summer", "none")
    with pytest.warns(UserWarning, match="6S ignores water_vapour_cm"):
        parse_params("6s", {"atmosphere_profile": "tropical", "water_vapour_cm": 2.0})
