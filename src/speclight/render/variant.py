"""Which Mitsuba / Dr.Jit variants work here, the order of preference, and activation.

Mitsuba's ``set_variant`` is process-wide state. A run chooses its variant once, in
:class:`speclight.render.session.RenderSession` (the only caller of :func:`choose_variant`
besides ``speclight info``), and every render of the run activates that same variant through
:func:`activate`. Order of preference: ``cuda_ad_*`` if a CUDA GPU works, ``llvm_ad_*`` if a
usable libLLVM (>= 16) is found, else ``scalar_*``.
libLLVM must be chosen before Dr.Jit is first imported (``DRJIT_LIBLLVM_PATH``); version 15
crashes Mitsuba's LLVM variants and is never used.

``SPECLIGHT_HIDE_LLVM=1`` in the environment makes a process behave as on a machine without
libLLVM 16-19 (the documented fallback: ``scalar_*`` variants and the numpy ray caster). It is
read by :func:`find_libllvm`, so every process honours it, Dask workers included: a local
cluster's workers inherit the environment of the process that starts them; the workers of an
existing cluster need it in the shell that starts them.
"""

from __future__ import annotations

import glob
import importlib.util
import os
import re
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from functools import lru_cache
from types import ModuleType

from speclight.errors import InputError, did_you_mean

#: libLLVM versions known to work with Dr.Jit 1.x, best first.
_LLVM_OK = (19, 18, 17, 16)
#: Environment variable: ``1`` hides every libLLVM (the LLVM backend is then unavailable).
HIDE_LLVM_ENV = "SPECLIGHT_HIDE_LLVM"
#: Environment variable: Dr.Jit threads (and numpy ray-caster processes) of one process, set
#: for each worker of a local Dask cluster (its share of the cores).
RENDER_THREADS_ENV = "SPECLIGHT_RENDER_THREADS"
_LLVM_DIRS = (
    "/usr/lib/x86_64-linux-gnu",
    "/usr/lib64",
    "/usr/lib",
    "/usr/local/lib",
    "/usr/lib/aarch64-linux-gnu",
    "/opt/homebrew/opt/llvm/lib",
    "/usr/local/opt/llvm/lib",
)


def llvm_hidden() -> bool:
    """True when ``SPECLIGHT_HIDE_LLVM`` is set (to anything but ``0`` or nothing)."""
    return os.environ.get(HIDE_LLVM_ENV, "").strip() not in ("", "0")


def render_threads() -> int | None:
    """This process's share of the cores (``SPECLIGHT_RENDER_THREADS``), or ``None``."""
    threads = os.environ.get(RENDER_THREADS_ENV, "").strip()
    return int(threads) if threads.isdigit() and int(threads) > 0 else None


def find_libllvm() -> str | None:
    """Path of a libLLVM shared library with version 16-19, or ``None`` (also when
    ``SPECLIGHT_HIDE_LLVM`` hides it)."""
    if llvm_hidden():
        return None
    env = os.environ.get("DRJIT_LIBLLVM_PATH")
    if env and os.path.exists(env) and _llvm_version(env) in _LLVM_OK:
        return env
    for version in _LLVM_OK:
        for d in _LLVM_DIRS:
            for pat in (
                f"libLLVM-{version}.so",
                f"libLLVM.so.{version}*",
                f"libLLVM-{version}.dylib",
                f"llvm-{version}/lib/libLLVM*.so*",
            ):
                hits = sorted(glob.glob(os.path.join(d, pat)))
                if hits:
                    return hits[0]
    return None


def _llvm_version(path: str) -> int | None:
    m = re.search(r"LLVM[-.](?:so\.)?(\d+)", os.path.basename(path)) or re.search(
        r"llvm-(\d+)", path
    )
    return int(m.group(1)) if m else None


def mitsuba_installed() -> bool:
    """True if the ``mitsuba`` and ``drjit`` packages can be imported."""
    return (
        importlib.util.find_spec("mitsuba") is not None
        and importlib.util.find_spec("drjit") is not None
    )


@contextmanager
def _stderr_silenced() -> Iterator[None]:
    """Silence file descriptor 2 (messages printed by native libraries) for a moment."""
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as devnull:
            os.dup2(devnull.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


@lru_cache(maxsize=1)
def _backends() -> tuple[bool, bool]:
    """(cuda works, llvm works), probed once; sets DRJIT_LIBLLVM_PATH before importing drjit."""
    if not mitsuba_installed():
        return False, False
    llvm_path = find_libllvm()
    if "drjit" not in sys.modules:
        if llvm_path:
            os.environ["DRJIT_LIBLLVM_PATH"] = llvm_path
        else:
            # Hide any unusable libLLVM (e.g. 15) so Dr.Jit does not pick it up; Dr.Jit then
            # reports the missing library on stderr, which the caller's notice replaces.
            os.environ["DRJIT_LIBLLVM_PATH"] = "/nonexistent/libLLVM.so"
            with _stderr_silenced():
                import drjit  # noqa: F401
    import drjit as dr

    threads = render_threads()
    if threads is not None:  # a Dask worker's share of the cores
        dr.set_thread_count(threads)
    cuda = bool(dr.has_backend(dr.JitBackend.CUDA))
    llvm = bool(llvm_path) and bool(dr.has_backend(dr.JitBackend.LLVM))
    return cuda, llvm


def engine_versions() -> dict[str, str]:
    """Versions of the render engines and the libLLVM used (for ``speclight info``)."""
    from importlib.metadata import PackageNotFoundError, version

    out: dict[str, str] = {}
    for pkg in ("mitsuba", "drjit"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    out["libllvm"] = libllvm_status()
    return out


def libllvm_status() -> str:
    """The libLLVM used, or why there is none (for ``speclight info``)."""
    missing = f"hidden by {HIDE_LLVM_ENV}" if llvm_hidden() else "not found"
    return find_libllvm() or f"{missing} (LLVM variants unavailable)"


def available_variants() -> list[str]:
    """Mitsuba variants that are compiled in and usable on this machine (for ``speclight info``)."""
    if not mitsuba_installed():
        return []
    cuda, llvm = _backends()
    import mitsuba as mi

    out = []
    for v in mi.variants():
        if v.startswith("cuda_") and not cuda:
            continue
        if v.startswith("llvm_") and not llvm:
            continue
        out.append(v)
    return out


def choose_variant(
    requested: str | None = None, spectral: bool = True, polarized: bool = False
) -> str:
    """Name of the Mitsuba variant to use.

    Parameters
    ----------
    requested
        An explicit variant (must be available) or ``None``/``"auto"`` for the best one.
    spectral
        Prefer ``*_spectral`` (path tracing) over ``*_rgb`` (ray casting only needs geometry).
    polarized
        Choose a ``*_spectral_polarized`` variant (polarised path tracing).

    Returns
    -------
    str
        E.g. ``llvm_ad_spectral``. Without Mitsuba installed the answer is ``"numpy"``: the
        single-scattering renderer then casts rays with its own numpy code.
    """
    avail = available_variants()
    if requested not in (None, "auto"):
        if requested == "numpy" or requested in avail:
            return requested
        raise InputError(
            f"render variant '{requested}' is not available{did_you_mean(requested, avail)} "
            f"(available: {', '.join([*avail, 'numpy']) or 'numpy'}; or 'auto')",
            field="render.variant",
        )
    if not avail:
        warnings.warn(
            "Mitsuba is not installed: single-scattering uses numpy ray casting, "
            "path mode is unavailable (pip install 'speclight[render]')",
            stacklevel=2,
        )
        return "numpy"
    tail = "spectral_polarized" if polarized else "spectral" if spectral else "rgb"
    for prefix in ("cuda_ad_", "llvm_ad_"):
        if prefix + tail in avail:
            return prefix + tail
    warnings.warn(
        f"no CUDA GPU and no libLLVM 16-19 found: falling back to the slow scalar_{tail} "
        "variant (install libLLVM >= 16 or set DRJIT_LIBLLVM_PATH)",
        stacklevel=2,
    )
    return "scalar_" + tail


def activate(variant: str) -> ModuleType:
    """Set the process-wide Mitsuba variant and return the ``mitsuba`` module."""
    _backends()
    import mitsuba as mi

    if mi.variant() != variant:
        mi.set_variant(variant)
    return mi
