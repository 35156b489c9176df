r"""Resumable outputs: the work folder of a Zarr store written chunk by chunk, shared by runs and sweeps.

A long run (:func:`~eulerpoisson.io.stream.solve_to_file`, ``simulate --out
run.zarr``) and a sweep (:func:`~eulerpoisson.sweep.run_sweep`) write their
store into a work folder ``.NAME.partial`` next to ``NAME``:

- ``store.zarr``: the store, readable while it is being written;
- ``state.json``: the fingerprint of the arguments (written last when the
  empty store is complete: a folder without it is discarded);
- ``done/CHUNK``: one marker per finished chunk, written *after* its data,
  with its counters.

:class:`PartialRun` owns that folder: what an existing output or a leftover
work folder means (nothing to do, an error, resume, or start afresh),
the markers, and the atomic publication (a rename) when every chunk is done.
Nothing finished is lost on Ctrl-C, a crash or a kill: the next run with the
same arguments resumes from the markers.

Examples
--------
>>> import tempfile, pathlib
>>> from eulerpoisson.io.resumable import PartialRun
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> run = PartialRun(d / "out.zarr", {"n": 3}, resume=True, overwrite=False)
>>> run.open(), run.done
(True, set())
>>> run.create(lambda store: store.mkdir())
>>> run.mark(0, {"seconds": 1.0}); sorted(run.done), run.infos()[0]["seconds"]
([0], 1.0)
>>> run.publish(); (d / "out.zarr").is_dir(), run.work.exists()
(True, False)
"""

from __future__ import annotations

import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import EulerPoissonError, InvalidInputError
from .formats import is_zarr_store

__all__ = [
    "PartialRun",
    "work_dir",
    "partial_store",
    "write_json_atomic",
    "mark_done",
    "done_chunks",
    "check_replaceable",
    "replace_dir",
]


def work_dir(path: Path) -> Path:
    """The work folder ``.NAME.partial`` of an output ``NAME``."""
    return path.with_name(f".{path.name}.partial")


def partial_store(path: str | os.PathLike[str]) -> Path:
    """The Zarr store where an unfinished run to ``path`` keeps its finished chunks.

    Readable while the run is going on or after it was interrupted
    (``xarray.open_zarr(partial_store(path))``); unfinished samples read as NaN.
    """
    return work_dir(Path(path)) / "store.zarr"


def write_json_atomic(path: Path, obj: Any) -> None:
    """Write ``obj`` as JSON to ``path`` atomically (a temporary file, then a rename)."""
    from .atomic import atomic_write_text

    atomic_write_text(path, json.dumps(obj, sort_keys=True, indent=1))


def mark_done(work: Path, k: int, info: dict) -> None:
    """The marker of finished chunk ``k`` (written after the chunk's data)."""
    write_json_atomic(work / "done" / f"{k:09d}", info)


def done_chunks(work: Path) -> set[int]:
    """The chunks with a marker."""
    d = work / "done"
    if not d.is_dir():
        return set()
    return {int(p.name) for p in d.iterdir() if p.name.isdigit()}


def check_replaceable(dest: Path) -> None:
    """FileExistsError when ``dest`` is a folder that is not a Zarr store (``overwrite`` must not delete it).

    Raises
    ------
    FileExistsError
        As said.
    """
    if dest.is_dir() and not dest.is_symlink() and not is_zarr_store(dest):
        raise FileExistsError(
            f"refusing to replace {dest}: it is a folder but not a Zarr store (overwrite only replaces "
            f"earlier results); remove it yourself or choose another path"
        )


def replace_dir(src: Path, dest: Path, overwrite: bool) -> None:
    """Move folder ``src`` to ``dest``; an existing ``dest`` is replaced only with ``overwrite``.

    Raises
    ------
    FileExistsError
        ``dest`` exists and ``overwrite`` is False, or it is a folder that is not a Zarr store.
    """
    if dest.exists() or dest.is_symlink():
        if not overwrite:
            raise FileExistsError(f"{dest} exists; pass overwrite=True to replace it")
        check_replaceable(dest)
        trash = dest.with_name(f".{dest.name}.old-{os.getpid()}")
        os.replace(dest, trash)
        os.replace(src, dest)
        if trash.is_dir() and not trash.is_symlink():
            shutil.rmtree(trash, ignore_errors=True)
        else:
            trash.unlink(missing_ok=True)
    else:
        os.replace(src, dest)


class PartialRun:
    """The work folder of one resumable output (see the module notes).

    Parameters
    ----------
    path : Path
        The output (a Zarr store once published).
    fingerprint : dict
        The arguments of the run (JSON): a leftover work folder resumes only with the same.
    resume : bool or "always"
        A run resumes its leftover work folder with ``True`` (otherwise it is an error, so that no work is
        thrown away by accident); a sweep (``"always"``) resumes whenever the arguments are the same.
    overwrite : bool
        Replace an existing output and discard a leftover work folder (of other arguments, for a sweep).
    finished : callable(Path) -> bool, optional
        Whether an existing output already holds this run (then there is nothing to do, see :meth:`open`).
    kind : str
        ``"run"`` or ``"sweep"``: the words of the messages.

    Attributes
    ----------
    path, work, store : Path
        The output, the work folder and the store inside it.
    done : set of int
        The finished chunks.
    """

    def __init__(
        self,
        path: Path,
        fingerprint: dict,
        *,
        resume: bool | str,
        overwrite: bool,
        finished: Callable[[Path], bool] | None = None,
        kind: str = "run",
    ) -> None:
        self.path = Path(path)
        self.fingerprint = fingerprint
        self.resume = resume
        self.overwrite = overwrite
        self.finished = finished
        self.kind = kind
        self.work = work_dir(self.path)
        self.store = self.work / "store.zarr"
        self.done: set[int] = set()

    def open(self) -> bool:
        """Check the output and the work folder; False when the output already holds this run (nothing to do).

        Raises
        ------
        FileExistsError
            The output exists (and does not hold this run) without ``overwrite``, or ``overwrite`` would
            replace a folder that is not a Zarr store.
        EulerPoissonError
            A leftover work folder without ``resume`` (a run), or of other arguments (a sweep).
        InvalidInputError
            A run resumed with other arguments than its leftover work folder's.
        """
        if self.overwrite:
            check_replaceable(self.path)  # before any work, not after
        if self.path.exists() and not self.overwrite:
            if self.resume and self.finished is not None and self.finished(self.path):
                return False  # the same run finished before: nothing to do
            if self.kind == "sweep":
                raise FileExistsError(
                    f"{self.path} exists and holds a different sweep (or no sweep); pass overwrite=True to replace it"
                )
            raise FileExistsError(f"{self.path} exists; pass overwrite=True to replace it")
        if self.work.exists():
            try:
                with open(self.work / "state.json", encoding="utf-8") as fh:
                    old = json.load(fh)
            except (OSError, ValueError):
                old = None  # interrupted while the store was being created: nothing was computed
            if self.resume == "always" and old == self.fingerprint:
                self.done = done_chunks(self.work)
            elif old is None or self.overwrite:
                shutil.rmtree(self.work)
            elif self.resume == "always":
                raise EulerPoissonError(
                    f"{self.work} holds a partial {self.kind} with a different configuration; "
                    "pass overwrite=True to discard it"
                )
            elif not self.resume:
                raise EulerPoissonError(
                    f"an interrupted run to {self.path} left its finished chunks in {self.work}; pass resume=True "
                    "to continue it or overwrite=True to discard it"
                )
            elif old != self.fingerprint:
                raise InvalidInputError(
                    f"resume=True: the partial run in {self.work} was started with different arguments "
                    "(body, initial state, times, method, options, chunk or variables); "
                    "pass overwrite=True to discard it"
                )
            else:
                self.done = done_chunks(self.work)
        return True

    def create(self, make_store: Callable[[Path], None]) -> None:
        """Create the work folder and the empty store (``make_store(store)``) unless it is being resumed."""
        if self.work.exists():
            return
        (self.work / "done").mkdir(parents=True)
        make_store(self.store)
        write_json_atomic(self.work / "state.json", self.fingerprint)  # last: the store is complete, resumable

    def mark(self, k: int, info: dict) -> None:
        """Chunk ``k`` is finished (call after its data is written)."""
        mark_done(self.work, k, info)
        self.done.add(k)

    def forget(self, k: int) -> None:
        """Chunk ``k`` is not finished after all (its data failed verification): its marker is removed."""
        (self.work / "done" / f"{k:09d}").unlink(missing_ok=True)
        self.done.discard(k)

    def infos(self) -> dict[int, dict]:
        """The markers' records by chunk (those unreadable are left out)."""
        out = {}
        for k in sorted(done_chunks(self.work)):
            try:
                with open(self.work / "done" / f"{k:09d}", encoding="utf-8") as fh:
                    out[k] = json.load(fh)
            except (OSError, ValueError):
                continue
        return out

    def publish(self) -> None:
        """Rename the finished store to the output (atomic) and remove the work folder."""
        replace_dir(self.store, self.path, self.overwrite)
        shutil.rmtree(self.work, ignore_errors=True)
