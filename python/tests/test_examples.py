"""The Python examples run and write their PNGs (no viewer)."""
import pathlib
import subprocess
import sys

import pytest

import clfractal

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"


def run(script, *args, cwd):
    r = subprocess.run([sys.executable, str(EXAMPLES / script), *args], capture_output=True, text=True, cwd=cwd)
    assert r.returncode == 0, r.stderr
    return r.stdout


def test_fd_isovalue_example(tmp_path):
    pytest.importorskip("matplotlib")
    out = run("fd_isovalue.py", "synthetic:noisy-sphere:32", "--out", "fd.png", cwd=tmp_path)
    # The library's recommendation, the one clfractal fd prints first.
    best = clfractal.analyse(clfractal.read_volume("synthetic:noisy-sphere:32").volume, noise_level=False).best
    assert f"recommended isovalue {best.isovalue:g} ({best.verdict})" in out, out
    assert (tmp_path / "fd.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_ld_mesh_example(tmp_path):
    pytest.importorskip("matplotlib")
    out = run("ld_mesh.py", "synthetic:noisy-sphere:24", "--no-viewer", "--window", "4", cwd=tmp_path)
    assert "triangles" in out
    assert (tmp_path / "mesh.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
