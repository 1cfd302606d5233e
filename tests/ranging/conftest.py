"""Shared fixtures for ranging tests: the ray-casting engines available here."""

import pytest

from speclight.render import available_variants


def _casters() -> list[str]:
    """numpy always; a vectorised Mitsuba variant when one works on this machine."""
    fast = [
        v for v in available_variants() if v.startswith(("cuda_", "llvm_")) and v.endswith("_rgb")
    ]
    return ["numpy", *fast[:1]]


@pytest.fixture(params=_casters())
def caster_variant(request: pytest.FixtureRequest) -> str:
    return request.param
