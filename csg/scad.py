"""``.scad`` files through the installed OpenSCAD: ``openscad -o model.csg model.scad``.

A ``.scad`` file is a program (modules, loops, ``include``); OpenSCAD evaluates
it and writes the flat ``.csg`` tree that :func:`csg.read_openscad` reads.
:func:`export_csg` runs the OpenSCAD found on the ``PATH`` (or named by
``$IMPLICITVOX_OPENSCAD``) on a temporary ``.csg`` file, within a time limit,
and hands back its text:

- OpenSCAD's ``WARNING:`` and ``DEPRECATED:`` lines become
  :class:`~csg.openscad_parser.OpenSCADWarning` s, with the file and line
  OpenSCAD names (OpenSCAD gives no column);
- its ``ERROR:`` lines (a syntax error, a recursion, an assertion) raise an
  :class:`~csg.openscad_parser.OpenSCADError` with the first error's file and
  line, even where OpenSCAD itself exits with status 0 and an empty export;
- ``ECHO:`` output is not passed on;
- a run longer than ``seconds`` is stopped: :class:`TimeoutError`;
- without OpenSCAD, :class:`OpenSCADNotFound` says to install it or to export
  the ``.csg`` with it elsewhere.

Examples
--------
>>> import os, tempfile
>>> folder = tempfile.mkdtemp()
>>> with open(os.path.join(folder, "part.scad"), "w") as fh:
...     _ = fh.write("module peg(h) { cylinder(h = h, r = 1); }\\n"
...                  "for (i = [0:2]) translate([3 * i, 0, 0]) peg(2 + i);\\n")
>>> try:
...     text = export_csg(os.path.join(folder, "part.scad"))
... except OpenSCADNotFound:      # no OpenSCAD here: nothing to show
...     text = None
>>> text is None or text.count("cylinder(") == 3
True
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile
import warnings
from typing import Any, Optional

from .openscad_parser import OpenSCADError, OpenSCADWarning

__all__ = ["export_csg", "openscad_binary", "OpenSCADNotFound", "OPENSCAD_SECONDS",
           "OPENSCAD_VARIABLE", "MESSAGE_BYTES", "CSG_BYTES"]

#: the longest an export may run, in seconds (a ``.scad`` program can loop for ever)
OPENSCAD_SECONDS = 120.0
#: the environment variable naming the ``openscad`` program (else it is found on the PATH)
OPENSCAD_VARIABLE = "IMPLICITVOX_OPENSCAD"
#: OpenSCAD's messages read at most (an ``echo`` in a long loop writes without end)
MESSAGE_BYTES = 1 << 20
#: the largest exported ``.csg`` read, in bytes (the parser bounds its tokens too)
CSG_BYTES = 1 << 30

_LOCATION = re.compile(r",? in file (?P<file>.+?), line (?P<line>\d+)\s*$")
_KINDS = ("ERROR:", "WARNING:", "DEPRECATED:", "TRACE:")


class OpenSCADNotFound(FileNotFoundError):
    """No ``openscad`` program to turn a ``.scad`` file into a ``.csg`` file."""


def openscad_binary() -> str:
    """The ``openscad`` program: ``$IMPLICITVOX_OPENSCAD``, else ``openscad`` on the PATH.

    Raises
    ------
    OpenSCADNotFound
        Neither is there; the message says how to go on.
    """
    named = os.environ.get(OPENSCAD_VARIABLE)
    found = shutil.which(named or "openscad")
    if found is None:
        where = f"${OPENSCAD_VARIABLE} names {named!r}, which" if named else \
            "'openscad' is not on the PATH and"
        raise OpenSCADNotFound(
            f"reading a .scad file needs OpenSCAD to evaluate it: {where} is not a program. "
            "Install OpenSCAD (apt-get install openscad, or https://openscad.org) or export "
            "the .csg with it (openscad -o part.csg part.scad) and read that")
    return found


def export_csg(path: Any, seconds: Optional[float] = None) -> str:
    """Evaluate a ``.scad`` file with OpenSCAD and return the ``.csg`` text it exports.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.scad`` file. ``include``, ``use`` and ``import`` resolve from
        its folder, as in OpenSCAD.
    seconds : float, optional
        Stop OpenSCAD after this long (default :data:`OPENSCAD_SECONDS`, read
        at the call).

    Returns
    -------
    str
        The ``.csg`` text (``import`` paths in it are relative to the ``.scad``
        file's folder).

    Raises
    ------
    OpenSCADNotFound
        OpenSCAD is not installed (:func:`openscad_binary`).
    OpenSCADError
        OpenSCAD reported an error: its message, file and line.
    TimeoutError
        OpenSCAD ran longer than ``seconds``.
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise FileNotFoundError(f"no such .scad file: {path}")
    seconds = OPENSCAD_SECONDS if seconds is None else seconds
    if not seconds > 0:
        raise ValueError(f"seconds must be positive, got {seconds!r}")
    program = openscad_binary()
    folder = os.path.dirname(os.path.abspath(path))
    with tempfile.TemporaryDirectory(prefix="implicitvox-scad-") as tmp:
        out = os.path.join(tmp, "export.csg")
        log = os.path.join(tmp, "messages.txt")
        with open(log, "wb") as messages:
            try:
                status = subprocess.run([program, "-o", out, os.path.abspath(path)],
                                        stdin=subprocess.DEVNULL, stdout=messages,
                                        stderr=messages, cwd=folder, timeout=seconds,
                                        check=False).returncode
            except subprocess.TimeoutExpired:
                raise TimeoutError(f"{path}: OpenSCAD did not finish exporting the .csg within "
                                   f"{seconds:g} s (csg.scad.OPENSCAD_SECONDS)") from None
        with open(log, "rb") as messages:
            said = messages.read(MESSAGE_BYTES).decode("utf-8", errors="replace")
        _pass_on(said, path, status)
        if not os.path.isfile(out):
            raise OpenSCADError(f"OpenSCAD wrote no .csg (exit status {status})", 1, None, path)
        if os.path.getsize(out) > CSG_BYTES:
            raise OpenSCADError(f"the exported .csg is larger than {CSG_BYTES} bytes "
                                "(csg.scad.CSG_BYTES)", 1, None, path)
        with open(out, encoding="utf-8", errors="replace") as fh:
            return fh.read()


def _pass_on(said: str, path: str, status: int) -> None:
    """OpenSCAD's warnings as :class:`OpenSCADWarning` s; its first error raised."""
    error: Optional[tuple[str, str, int]] = None
    traces = []
    for raw in said.splitlines():
        kind = next((k for k in _KINDS if raw.startswith(k)), None)
        if kind is None:
            continue
        text = raw[len(kind):].strip()
        found = _LOCATION.search(text)
        where, line = path, 1
        if found:
            text = text[:found.start()]
            where = os.path.normpath(os.path.join(os.path.dirname(path), found["file"]))
            line = int(found["line"])
        if kind == "ERROR:" and error is None:
            error = (text, where, line)
        elif kind == "TRACE:" and error is not None and len(traces) < 3:
            trace = f"{text} at {where}:{line}"
            if trace not in traces:
                traces.append(trace)
        elif kind in ("WARNING:", "DEPRECATED:"):
            warnings.warn(f"{where}:{line}: {text} (OpenSCAD)", OpenSCADWarning, stacklevel=4)
    if error is not None:
        text, where, line = error
        trace = "".join(f"; {t}" for t in traces)
        raise OpenSCADError(f"OpenSCAD: {text}{trace}", line, None, where)
    if status != 0:
        last = [s for s in said.splitlines() if s.strip()][-1:] or ["no message"]
        raise OpenSCADError(f"OpenSCAD failed (exit status {status}): {last[0].strip()}", 1,
                            None, path)
