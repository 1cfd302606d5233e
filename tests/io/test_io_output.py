"""Claiming an output: bad names refused first, one run per output, left-overs removed."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from speclight.errors import InputError
from speclight.io.output import OutputClaim, OutputWriteError, check_output_path, lock_path

HOLD = (
    "import sys\n"
    "from speclight.io.output import OutputClaim\n"
    "with OutputClaim(sys.argv[1]):\n"
    "    print('held', flush=True)\n"
    "    sys.stdin.read()\n"
)


@contextmanager
def _held_by_another_process(output: Path) -> Iterator[subprocess.Popen[str]]:
    """A second process holding the claim on ``output`` until the block ends."""
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(output)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "held\n"
        yield holder
    finally:
        if holder.poll() is None:
            holder.kill()
        holder.communicate()


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_second_claim_fails_at_once_naming_the_holder(tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    with _held_by_another_process(out) as holder:
        for force in (False, True):
            with pytest.raises(InputError, match=rf"another speclight run \(PID {holder.pid}\)"):
                OutputClaim(out, force=force).__enter__()
        holder.communicate("")  # the holder ends its run
    with OutputClaim(out) as claim:
        claim.write(b"result")
    assert out.read_bytes() == b"result"
    assert [p.name for p in tmp_path.iterdir()] == ["out.nc"]


def test_the_lock_of_a_killed_run_is_taken_over(tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    with _held_by_another_process(out) as holder:
        holder.kill()
        holder.wait()
    assert lock_path(out).read_text().strip() == str(holder.pid)  # SIGKILL leaves it behind
    with OutputClaim(out) as claim:
        assert lock_path(out).read_text().strip() == str(os.getpid())
        claim.write(b"result")
    assert [p.name for p in tmp_path.iterdir()] == ["out.nc"]


def test_leftovers_of_killed_runs_are_removed_and_nothing_else(tmp_path: Path) -> None:
    dead = _dead_pid()
    leftovers = [
        f".out.nc.speclight-{dead}-0a1b2c3d.tmp",  # of this output
        f".other.nc.speclight-{dead}-deadbeef.tmp",  # of another output, nobody holds it
        ".gone.nc.speclight.lock",  # the lock of a killed run
    ]
    kept = ["notes.txt", ".out.nc.swp", ".busy.nc.speclight-1-00ff00ff.tmp"]
    with _held_by_another_process(tmp_path / "busy.nc"):  # a live run: its files stay
        for name in leftovers + kept:
            (tmp_path / name).write_text("x")
        with OutputClaim(tmp_path / "out.nc"):
            pass
        names = {p.name for p in tmp_path.iterdir()}
    assert names == {*kept, ".busy.nc.speclight.lock"}


def test_output_is_written_with_the_umask_permissions(tmp_path: Path) -> None:
    previous = os.umask(0o027)
    try:
        with OutputClaim(tmp_path / "out.nc") as claim:
            claim.write(b"result")
    finally:
        os.umask(previous)
    assert (tmp_path / "out.nc").stat().st_mode & 0o777 == 0o640


def test_a_file_that_appears_during_the_run_is_not_overwritten(tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    with OutputClaim(out) as claim:
        out.write_text("another program's file")
        with pytest.raises(OutputWriteError, match="appeared during the run"):
            claim.write(b"result")
    assert out.read_text() == "another program's file"
    assert [p.name for p in tmp_path.iterdir()] == ["out.nc"]


def test_force_replaces_an_existing_file(tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    out.write_text("old")
    with OutputClaim(out, force=True) as claim:
        claim.write(b"new")
    assert out.read_text() == "new"


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("", "the file name is empty"),
        (".", "names a folder; give a file name such as out.nc"),
        ("sub", "sub names a folder"),
        ("new/", "new/ names a folder"),
        ("nope/out.nc", "folder nope of nope/out.nc does not exist"),
        ("s.yaml/out.nc", "s.yaml in s.yaml/out.nc is a file, not a folder"),
        ("s.yaml", "s.yaml is the scenario file"),
        ("sub/../s.yaml", "sub/../s.yaml is the scenario file"),
        ("link.yaml", "link.yaml is the scenario file"),
        ("old.nc", "old.nc exists; choose another name or pass --force"),
    ],
)
def test_bad_output_names_are_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, name: str, message: str
) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    Path("s.yaml").write_text("name: x\n")
    Path("link.yaml").symlink_to("s.yaml")
    Path("old.nc").write_text("keep")
    with pytest.raises(InputError, match=message) as info:
        check_output_path(name, inputs={"scenario file": Path("s.yaml")})
    assert str(info.value).startswith("--output: ")
    assert Path("s.yaml").read_text() == "name: x\n" and Path("old.nc").read_text() == "keep"


def test_force_does_not_replace_what_is_not_a_file() -> None:
    with pytest.raises(InputError, match="not a regular file"):
        check_output_path("/dev/null", force=True)


@pytest.mark.skipif(not Path("/proc/self").exists(), reason="needs Linux /proc")
def test_a_folder_where_no_file_can_be_created_is_refused_before_work() -> None:
    # /proc exists but takes no new files, even for root
    with pytest.raises(InputError, match="cannot write in folder /proc"):
        OutputClaim("/proc/out.nc").__enter__()


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write in any folder")
def test_an_unwritable_folder_is_refused_before_work(tmp_path: Path) -> None:
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o500)
    with pytest.raises(InputError, match="cannot write in folder"):
        OutputClaim(locked / "out.nc").__enter__()
