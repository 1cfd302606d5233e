"""Hostile variants of the files the estimation commands read (issue 22, item 3).

Each family turns a valid file into one a user (or a broken disk, a cut download, a
spreadsheet) could give: a measured CSV with odd epochs, cells or columns; a NetCDF that is
damaged, laid out otherwise or holds odd values; an OBSERVATIONS CSV; a FIT.json; an IERS
table; and paths that cannot be read. The tests in ``test_fuzz_estimation.py`` run every
command on every family that fits its files.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import xarray as xr

# --- measured CSV (time, band..., optionally band_sigma...) ----------------------------------


def _rows(text: str) -> tuple[str, list[str]]:
    lines = text.splitlines()
    return lines[0], lines[1:]


def _each_row(f: Callable[[str], str]) -> Callable[[str], str]:
    def spoil(text: str) -> str:
        head, rows = _rows(text)
        return "\n".join([head] + [f(r) for r in rows]) + "\n"

    return spoil


def _cells(f: Callable[[int, list[str]], None]) -> Callable[[str], str]:
    """Apply ``f(row index, cells)`` to the cells of every data row."""

    def spoil(text: str) -> str:
        head, rows = _rows(text)
        out = [head]
        for i, row in enumerate(rows):
            cells = row.split(",")
            f(i, cells)
            out.append(",".join(cells))
        return "\n".join(out) + "\n"

    return spoil


def _all_rates(value: str) -> Callable[[str], str]:
    return _cells(lambda i, c: c.__setitem__(slice(1, None), [value] * (len(c) - 1)))


def _one_rate(value: str, row: int = 3) -> Callable[[str], str]:
    return _cells(lambda i, c: c.__setitem__(1, value) if i == row else None)


def _with_sigma(value: str) -> Callable[[str], str]:
    def spoil(text: str) -> str:
        head, rows = _rows(text)
        bands = head.split(",")[1:]
        out = [head + "," + ",".join(f"{b}_sigma" for b in bands)]
        out += [row + "," + ",".join([value] * len(bands)) for row in rows]
        return "\n".join(out) + "\n"

    return spoil


def _header(f: Callable[[list[str]], list[str]], rows: Callable[[str], str] = str) -> Callable:
    def spoil(text: str) -> str:
        head, body = _rows(text)
        return ",".join(f(head.split(","))) + "\n" + "\n".join(rows(r) for r in body) + "\n"

    return spoil


def _year(year: str) -> Callable[[str], str]:
    return _each_row(lambda row: year + row[row.index("-", 1) :])


MEASURED_CSV: dict[str, Callable[[str], str]] = {
    # epochs: DE421 covers 1899-07-30..2053-10-08; datetime64[ns] wraps outside 1678..2262
    **{f"year {y}": _year(y) for y in ("0001", "1600", "1899", "2200", "9999", "-0001")},
    "shifted a day": _each_row(lambda row: row.replace("2019-08-30", "2019-08-31", 1)),
    "reversed rows": lambda text: "\n".join([_rows(text)[0], *_rows(text)[1][::-1]]) + "\n",
    "repeated row": lambda text: text + _rows(text)[1][-1] + "\n",
    "UTC offset": _each_row(lambda row: row.replace("Z,", "+02:00,", 1)),
    # spreadsheet forms (accepted)
    "byte-order mark": lambda text: "\ufeff" + text,
    "CRLF": lambda text: text.replace("\n", "\r\n"),
    "padded header": _header(lambda cells: [f"  {c} " for c in cells]),
    "quoted header": _header(lambda cells: [f'"{c}"' for c in cells]),
    "trailing commas": lambda text: "\n".join(f"{line}," for line in text.splitlines()) + "\n",
    "trailing commas in rows": _each_row(lambda row: row + ","),
    # columns
    "missing band": lambda text: "\n".join(ln.rsplit(",", 1)[0] for ln in text.splitlines()),
    "wrong names": _header(lambda cells: ["time", *(f"X{i}" for i in range(len(cells) - 1))]),
    "duplicate band": _header(lambda cells: ["time", *[cells[1]] * (len(cells) - 1)]),
    "extra named column": _header(lambda cells: [*cells, "airmass"], lambda r: r + ",1.2"),
    "extra unnamed column": _header(lambda cells: [*cells, ""], lambda r: r + ",1"),
    "empty header cell": _header(lambda cells: ["time", "", *cells[2:]]),
    "semicolons": lambda text: text.replace(",", ";"),
    # values
    "all zero": _all_rates("0"),
    "all negative": _all_rates("-5"),
    "all nan": _all_rates("nan"),
    "all empty": _all_rates(""),
    "denormal": _all_rates("5e-324"),
    "tiny": _all_rates("1e-300"),
    "all huge": _all_rates("1e300"),
    "one huge": _one_rate("1e300"),
    "one inf": _one_rate("inf"),
    "one Infinity": _one_rate("Infinity"),
    "one overflow": _one_rate("1e309"),
    "one word": _one_rate("bright"),
    "sigma 0": _with_sigma("0"),
    "sigma tiny": _with_sigma("1e-300"),
    "sigma denormal": _with_sigma("5e-324"),
    "sigma huge": _with_sigma("1e300"),
    "sigma negative": _with_sigma("-1"),
    # whole files
    "one row": lambda text: "\n".join(text.splitlines()[:2]) + "\n",
    "two rows": lambda text: "\n".join(text.splitlines()[:3]) + "\n",
    "header only": lambda text: text.splitlines()[0] + "\n",
    "empty": lambda text: "",
    "cut mid-line": lambda text: text[: len(text) // 2],
    "NUL byte": lambda text: text[:40] + "\x00" + text[40:],
}

# --- NetCDF (a speclight dataset) --------------------------------------------------------------


def _nc(ds: xr.Dataset) -> bytes:
    ds = ds.copy(deep=True)
    for var in ds.variables.values():
        var.encoding = {}
    return bytes(ds.to_netcdf(None, engine="h5netcdf"))


def _set(name: str, value: float, where: tuple = (slice(None),)) -> Callable[[xr.Dataset], bytes]:
    def spoil(ds: xr.Dataset) -> bytes:
        ds = ds.copy(deep=True)
        ds[name].values[where] = value
        return _nc(ds)

    return spoil


GEOMETRY = ["phase_vector_body", "attitude_quaternion", "observer_direction_body"]
NETCDF: dict[str, Callable[[xr.Dataset], bytes]] = {
    # layout
    "extra dimension": lambda ds: _nc(ds.assign(count_rate=ds["count_rate"].expand_dims(extra=2))),
    "renamed time": lambda ds: _nc(ds.rename({"time": "epoch"})),
    "float time": lambda ds: _nc(ds.assign_coords(time=np.arange(ds.sizes["time"], dtype=float))),
    "time without values": lambda ds: _nc(ds.drop_vars("time")),
    "text rates": lambda ds: _nc(ds.assign(count_rate=ds["count_rate"].astype(str))),
    "2-vectors": lambda ds: _nc(ds.isel(xyz=[0, 1])),
    "no count rates": lambda ds: _nc(
        ds.drop_vars(["count_rate", "count_rate_measured"], errors="ignore")
    ),
    "no geometry": lambda ds: _nc(ds.drop_vars([*GEOMETRY, "sun_direction_body", "phase_angle"])),
    "no scenario": lambda ds: _nc(ds.drop_attrs()),
    "bad scenario": lambda ds: _nc(ds.assign_attrs(scenario_yaml="time: [")),
    "duplicate bands": lambda ds: _nc(
        ds.assign_coords(band=[str(ds.band.values[0])] * ds.sizes["band"])
    ),
    "no epochs": lambda ds: _nc(ds.isel(time=slice(0, 0))),
    "one epoch": lambda ds: _nc(ds.isel(time=[0])),
    "reversed time": lambda ds: _nc(ds.assign_coords(time=ds.time.values[::-1])),
    "year 2219": lambda ds: _nc(ds.assign_coords(time=ds.time.values + np.timedelta64(73000, "D"))),
    # values
    "NaN phase vectors": _set("phase_vector_body", np.nan),
    "NaN attitude": _set("attitude_quaternion", np.nan),
    "inf rates": _set("count_rate", np.inf),
    "one inf rate": _set("count_rate", np.inf, (3, 0)),
    "NaN rates": _set("count_rate", np.nan),
    "zero rates": _set("count_rate", 0.0),
    "NaN factors": _set("reflectance_factor", np.nan),
    "inf factor": _set("reflectance_factor", np.inf, (3, 0)),
    "NaN irradiance": _set("solar_irradiance", np.nan),
}


def damaged(raw: bytes, seed: int) -> bytes:
    """``raw`` with 32 random bytes written over a random place (past the signature)."""
    rng = np.random.default_rng(seed)
    spoilt = bytearray(raw)
    at = int(rng.integers(8, len(raw) - 32))
    spoilt[at : at + 32] = rng.bytes(32)
    return bytes(spoilt)


NETCDF_BYTES: dict[str, Callable[[bytes], bytes]] = {
    "random bytes": lambda raw: np.random.default_rng(0).bytes(4096),
    "HDF5 signature, random rest": lambda raw: raw[:8] + np.random.default_rng(1).bytes(4096),
    "truncated": lambda raw: raw[: len(raw) // 2],
    "empty": lambda raw: b"",
    "NetCDF-3 signature": lambda raw: b"CDF\x01" + raw[4:],
    "damaged": lambda raw: damaged(raw, 5),
}

# --- other files ---------------------------------------------------------------------------------


def _observation(column: int, value: str, row: int = 0) -> Callable[[str], str]:
    """Set a cell of an OBSERVATIONS CSV (``#`` lines and the header are kept)."""

    def spoil(text: str) -> str:
        lines = text.splitlines()
        first = next(i for i, ln in enumerate(lines) if not ln.startswith("#")) + 1
        cells = lines[first + row].split(",")
        cells[column] = value
        lines[first + row] = ",".join(cells)
        return "\n".join(lines) + "\n"

    return spoil


OBSERVATIONS_CSV: dict[str, Callable[[str], str]] = {
    "year 0001": _observation(0, "0001-08-30T02:20:00Z"),
    "year 2200": _observation(0, "2200-08-30T02:20:00Z"),
    "shifted a day": lambda text: text.replace("2019-08-30", "2019-08-31"),
    "byte-order mark": lambda text: "\ufeff" + text,
    "trailing commas": lambda text: "\n".join(
        ln if ln.startswith("#") else ln + "," for ln in text.splitlines()
    ),
    "magnitude inf": _observation(1, "inf"),
    "magnitude 1e300": _observation(1, "1e300"),
    "sigma 0": _observation(2, "0"),
    "unknown band": _observation(3, "G-999/26"),
    "no site": lambda text: "\n".join(ln for ln in text.splitlines() if ln[:2] != "# "),
    "binary": lambda text: "\x00\x01\x02",
    "empty": lambda text: "",
}

FIT_JSON: dict[str, Callable[[str], str]] = {
    "deep nesting": lambda text: "[" * 100_000 + "]" * 100_000,
    "5,001 digits": lambda text: text.replace("0.5", "1" * 5001, 1),
    "NaN albedo": lambda text: text.replace("0.5", "NaN", 1),
    "Infinity albedo": lambda text: text.replace("0.5", "Infinity", 1),
    "1e400 albedo": lambda text: text.replace("0.5", "1e400", 1),
    "text albedo": lambda text: text.replace("0.5", '"0.5"', 1),
    "no bands": lambda text: "{}",
    "a list": lambda text: "[1, 2]",
    "not JSON": lambda text: "{bands: 0.5",
    "empty": lambda text: "",
}

IERS_TABLE: dict[str, Callable[[str], str]] = {
    "cut mid-line": lambda text: text[: text.rstrip("\n").rfind("\n") + 66],
    "last 90 days": lambda text: "\n".join(text.splitlines()[-90:]) + "\n",
    "days not increasing": lambda text: "\n".join(text.splitlines()[::-1]) + "\n",
    "comma-separated": lambda text: "MJD,UT1-UTC\n60000,0.1\n",
    "binary": lambda text: "\x00" * 64,
    "empty": lambda text: "",
}
