"""Shared fixtures for render tests: the ray-casting engines available here."""

import pytest

from speclight.render import available_variants


def casters() -> list[str]:
    """numpy always; a vectorised Mitsuba variant when one works on this machine."""
    out = ["numpy"]
    fast = [
        v for v in available_variants() if v.startswith(("cuda_", "llvm_")) and v.endswith("_rgb")
    ]
    if fast:
        out.append(fast[0])
    return out


@pytest.fixture(params=casters())
def caster_variant(request: pytest.FixtureRequest) -> str:
    return request.param
