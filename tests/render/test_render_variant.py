"""Variant choice: one place, the right preference order, helpful errors."""

import pytest

from speclight.errors import InputError
from speclight.render import available_variants, choose_variant, find_libllvm
from speclight.render.variant import _llvm_version


def test_libllvm_15_is_never_chosen():
    path = find_libllvm()
    if path is not None:
        assert _llvm_version(path) in (16, 17, 18, 19)


@pytest.mark.parametrize(
    ("name", "version"),
    [("libLLVM-19.so", 19), ("libLLVM.so.18.1", 18), ("libLLVM-15.so", 15)],
)
def test_llvm_version_parsing(name, version):
    assert _llvm_version("/usr/lib/" + name) == version


def test_auto_choice_follows_preference_order():
    avail = available_variants()
    chosen = choose_variant(None, spectral=True)
    if any(v.startswith("cuda_") for v in avail):
        assert chosen.startswith("cuda_ad_")
    elif any(v.startswith("llvm_") for v in avail):
        assert chosen == "llvm_ad_spectral"
    elif avail:
        assert chosen == "scalar_spectral"
    else:
        assert chosen == "numpy"
    if avail:
        assert choose_variant(None, spectral=False).endswith("_rgb")


def test_unknown_variant_is_an_input_error_with_a_hint():
    if "llvm_ad_rgb" not in available_variants():
        pytest.skip("llvm variant not available here")
    with pytest.raises(InputError, match="did you mean 'llvm_ad_rgb'"):
        choose_variant("llvm_ad_rbg")


def test_import_speclight_does_not_import_mitsuba():
    import subprocess
    import sys

    code = (
        "import sys, speclight, speclight.render, speclight.target; print('mitsuba' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
