"""Every gallery script runs (at a small resolution) and writes its pictures."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

GALLERY = Path(__file__).resolve().parents[1] / "gallery"
SCRIPTS = sorted(GALLERY.glob("*/plot_*.py"))


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.name for s in SCRIPTS])
def test_gallery_script_runs(script, tmp_path):
    if 'which("openscad")' in script.read_text() and shutil.which("openscad") is None:
        pytest.skip("the script reads .scad files: OpenSCAD is not installed "
                    "(apt-get install openscad)")
    env = dict(os.environ, IMPLICITVOX_GALLERY_RES="40", IMPLICITVOX_GALLERY_OUT=str(tmp_path),
               VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    proc = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert list(tmp_path.glob("*.png")), "the script wrote no picture"


def test_gallery_has_scripts_that_import_the_package_plainly():
    assert len(SCRIPTS) >= 2
    for script in SCRIPTS:
        assert "sys.path" not in script.read_text(), f"{script.name} edits sys.path"


def test_the_gallery_command_names_its_folders_and_refuses_unknown_ones(capsys):
    from implicitvox import gallery
    assert {p.parent.name for p in gallery.scripts()} >= {"01-surfaces", "06-fields"}
    with pytest.raises(ValueError, match="no gallery folder"):
        gallery.scripts(["no-such-folder"])
