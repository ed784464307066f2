"""Python gives what the command line gives, with the same defaults: clfractal.report writes
clfractal report's page, Analysis.to_dict() is its --json, and every record's to_dict() is
plain JSON."""
import json
import os
import re

import numpy as np
import pytest

import clfractal
from conftest import gnuplot_runs, noisy_sphere, write_raw

# Entries that time the run: the only numbers two runs of the same analysis may differ in.
TIMINGS = {"seconds", "seconds_analysis", "seconds_prepare", "seconds_components"}
# The page's own entries (clfractal report --json, not the analysis).
PAGE_ONLY = {"volume", "device", "views", "explore", "seconds"}


def untimed(x):
    """`x` without its timing entries, at every depth."""
    if isinstance(x, dict):
        return {k: untimed(v) for k, v in x.items() if k not in TIMINGS}
    if isinstance(x, list):
        return [untimed(v) for v in x]
    return x


def untimed_page(html):
    return re.sub(r'(data-json="/seconds" data-digits="3">)[^<]*', r"\1", html)


# A held-out real scan (16-bit, the recommendations' components and the ladder) and two
# phantoms: a clean ball, and one with no clean isovalue (the denoising ladder runs).
CASES = ["walnut_128x96x114_uint16.raw", "ball4", "ball40"]


@pytest.fixture(params=CASES)
def volume_file(request, tmp_path, shared_data):
    name = request.param
    if name.startswith("ball"):
        return write_raw(tmp_path, name, noisy_sphere((36, 34, 38), np.uint8, seed=7, amplitude=float(name[4:])))
    path = shared_data / name
    if not path.exists():
        pytest.skip(f"{path} not found")
    if name.startswith("walnut"):  # a 64 x 48 x 57 crop keeps the suite short
        v = np.fromfile(path, dtype="<u2").reshape(114, 96, 128)[::2, ::2, ::2]
        return write_raw(tmp_path, "walnut_half", np.ascontiguousarray(v))
    return path


def test_report_writes_the_commands_page_and_analyse_its_answer(volume_file, cli, gnuplot, tmp_path):
    cli("report", volume_file, "-o", tmp_path / "cli.html", "--json", tmp_path / "cli.json")
    got = clfractal.report(volume_file, tmp_path / "py.html", json_path=tmp_path / "py.json")
    want = json.loads((tmp_path / "cli.json").read_text())
    assert untimed(got) == untimed(want)
    assert json.loads((tmp_path / "py.json").read_text()) == got
    page, want_page = (tmp_path / "py.html").read_text(), (tmp_path / "cli.html").read_text()
    assert untimed_page(page) == untimed_page(want_page) and page.count("data-json=") > 50

    # analyse() with its defaults is the report's analysis; to_dict() is plain JSON.
    v = clfractal.read_volume(volume_file)
    a = clfractal.analyse(v)
    d = json.loads(json.dumps(a.to_dict(), allow_nan=False))
    assert untimed(d) == untimed({k: x for k, x in want.items() if k not in PAGE_ONLY})
    assert d["noise"]["sigma"] == want["noise"]["sigma"] and d["recommended"] == want["recommended"]
    assert [r.to_dict()["isovalue"] for r in a.recommended] == [e["isovalue"] for e in want["recommended"]]
    json.dumps([r.to_dict() for r in a.recommended], allow_nan=False)

    # The notebook's view: the answer, the recommendations and the curve.
    h = a._repr_html_()
    best = want["recommended"][0]
    assert f"<td>{best['isovalue']:.8g}</td>" in h and "<svg" in h and "<polyline" in h
    assert ("Use isovalue" in h) == want["clean"]


def test_report_of_an_array(gnuplot, tmp_path):
    v = noisy_sphere((30, 28, 26), np.uint8, seed=2, amplitude=4.0)
    j = clfractal.report(v, tmp_path / "a.html", name="ball", spacing=(2.0, 1.0, 0.5), static=True)
    page = (tmp_path / "a.html").read_text()
    assert j["volume"]["file"] == "ball" and j["volume"]["spacing"] == [0.5, 1.0, 2.0]
    assert j["volume"]["dims"] == [26, 28, 30] and j["explore"] == {"static": "--static"}
    assert "NumPy array (z, y, x) = (30, 28, 26) uint8" in page and "<script" not in page


def test_report_refuses_bad_arguments_and_writes_nothing(tmp_path):
    v = noisy_sphere((30, 28, 26), np.uint8, seed=2, amplitude=4.0)
    with pytest.raises(ValueError, match="spacing"):
        clfractal.report(v, tmp_path / "b.html", spacing=(1.0, 0.0, 1.0))
    with pytest.raises(TypeError, match="read options"):
        clfractal.report(v, tmp_path / "b.html", dims=(1, 2, 3))
    with pytest.raises(ValueError, match="missing.raw"):
        clfractal.report(tmp_path / "missing.raw", tmp_path / "b.html")
    assert not (tmp_path / "b.html").exists()


def test_report_without_a_working_gnuplot_is_one_error_and_no_page(tmp_path):
    # Where gnuplot cannot draw (the wheel's test hides its libpng), the page is refused
    # whole with an error naming gnuplot, and nothing is left at the path.
    if gnuplot_runs():
        pytest.skip("gnuplot draws here; the failure path is exercised where it cannot")
    v = noisy_sphere((30, 28, 26), np.uint8, seed=2, amplitude=4.0)
    with pytest.raises(ValueError, match="gnuplot"):
        clfractal.report(v, tmp_path / "c.html", static=True)
    assert not (tmp_path / "c.html").exists()


def test_every_record_is_json(cli, tmp_path):
    v = noisy_sphere((24, 22, 20), np.uint8, seed=5, amplitude=30.0)
    path = write_raw(tmp_path, "v", v)
    records = [clfractal.noise_level(v), clfractal.fd4(v), clfractal.analyse(v, denoise=False),
               clfractal.small_components(v, 100, 2), clfractal.smooth(v, 100, 2.2),
               clfractal.targeted_filter(v, 100, 2.2), clfractal.info(path), clfractal.fd_curve(v)]
    for r in records:
        json.dumps(r.to_dict(), allow_nan=False)
    # Where the command line writes the same record, the same object.
    cli("fd", path, "--noise-level", "--isovalues", "100", "--json", tmp_path / "fd.json")
    noise = json.loads((tmp_path / "fd.json").read_text())["noise"]
    noise.pop("surface", None)
    assert untimed(records[0].to_dict()) == untimed(noise)
    cli("fd4", path, "--json", tmp_path / "fd4.json")
    want = json.loads((tmp_path / "fd4.json").read_text())
    assert {k: want[k] for k in records[1].to_dict()} == records[1].to_dict()


# ------------------------------------------------------------------ the PyPI PoCL's CPUs

ZEN3 = "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\nmodel\t\t: 1\nmodel name\t: AMD EPYC 7763\n\n"
ZEN5 = "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 26\nmodel\t\t: 2\nmodel name\t: AMD EPYC 9575F\n\n"
INTEL6 = "processor\t: 0\nvendor_id\t: GenuineIntel\ncpu family\t: 6\nmodel\t\t: 207\nmodel name\t: Xeon\n\n"
INTEL19 = "processor\t: 0\nvendor_id\t: GenuineIntel\ncpu family\t: 19\nmodel\t\t: 1\nmodel name\t: Xeon\n\n"


def test_cpus_the_pypi_pocl_cannot_name():
    assert clfractal._llvm14_unknown_cpu(ZEN3) is None and clfractal._llvm14_unknown_cpu(INTEL6) is None
    assert clfractal._llvm14_unknown_cpu(ZEN5) == "AuthenticAMD family 26 (AMD EPYC 9575F)"
    assert clfractal._llvm14_unknown_cpu(INTEL19).startswith("GenuineIntel family 19")
    assert clfractal._llvm14_unknown_cpu("") is None


@pytest.mark.parametrize("cpu", ["zen3", "zen5"])
def test_the_pypi_pocl_is_left_out_where_it_cannot_build(cpu, monkeypatch, tmp_path):
    # The failure path forced: no registered driver, the PyPI PoCL present, the CPU read from a file.
    info = tmp_path / "cpuinfo"
    info.write_text(ZEN3 if cpu == "zen3" else ZEN5)
    # A copy of the environment, so that the variable the call sets stays in this test.
    env = {k: v for k, v in os.environ.items() if k not in ("OCL_ICD_VENDORS", "OPENCL_VENDOR_PATH")}
    monkeypatch.setattr(clfractal.os, "environ", env)
    monkeypatch.setattr(clfractal.glob, "glob", lambda pattern: [])
    monkeypatch.setattr(clfractal, "_wheel_pocl", lambda: "/site/pyopencl/.libs/libpocl-x.so")
    said = clfractal._choose_opencl_drivers(str(info))
    if cpu == "zen3":
        assert said == "pocl-binary-distribution: /site/pyopencl/.libs/libpocl-x.so"
        assert env["OCL_ICD_VENDORS"] == "/site/pyopencl/.libs/libpocl-x.so"
    else:
        assert said.startswith("none (pocl-binary-distribution's PoCL 3.0 cannot build kernels for AuthenticAMD "
                               "family 26") and "apt install pocl-opencl-icd" in said and "pocl/pocl#1049" in said
        assert "OCL_ICD_VENDORS" not in env


def test_no_device_error_names_what_to_install(tmp_path):
    # No driver at all (an empty vendor directory): the error says what to install and where it looked.
    import subprocess
    import sys
    env = dict(os.environ, OCL_ICD_VENDORS=str(tmp_path))
    env.pop("CLFRACTAL_DEVICE_TYPE", None)
    probe = "import numpy as np, clfractal\ntry:\n    clfractal.fd_curve(np.zeros((4, 4, 4), np.uint8))\n" \
            "except RuntimeError as e:\n    print(e)\n"
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True, timeout=120)
    assert "pip install 'clfractal[cpu]'" in out.stdout and f"drivers: OCL_ICD_VENDORS={tmp_path}" in out.stdout, \
        out.stdout + out.stderr


# ------------------------------------------------------------------ the docs' table

READ_OPTIONS = {"--dims", "--type", "--endian", "--spacing", "--series", "--scaled", "--as"}


def test_the_docs_table_maps_every_command_and_option(cli):
    import inspect
    import pathlib
    page = (pathlib.Path(__file__).parents[2] / "docs" / "guide" / "python.md").read_text()
    table = page[page.index("## The command line in Python"):]
    rows = re.findall(r"^\| `([a-z0-9]+)` \|\s*([^|]*?)\s*\| (.*) \|$", table, re.M)
    assert rows
    documented = {}
    for command, options, python in rows:
        documented.setdefault(command, set()).update(re.findall(r"--[a-z0-9-]+", options))
        # Every call named exists, with every keyword named.
        for name, args in re.findall(r"`([A-Za-z_]+)(?:\(([^`]*)\))?`", python):
            if name in ("v", "mu", "iso"):
                continue
            assert hasattr(clfractal, name), f"{command}: clfractal.{name} does not exist"
            f = getattr(clfractal, name)
            params = inspect.signature(f.__init__ if inspect.isclass(f) else f).parameters
            for keyword in re.findall(r"(\w+)=", args or ""):
                assert keyword in params, f"{command}: {name} has no keyword {keyword}"
    commands = re.findall(r"^  ([a-z0-9]+)  ", cli("--help"), re.M)
    assert "report" in commands and "fd" in commands
    for command in commands:
        assert command in documented, f"clfractal {command} is not in docs/guide/python.md's table"
        given = set(re.findall(r"^\s+(?:-\w,\s*)?(--[a-z0-9-]+)", cli(command, "--help"), re.M)) - {"--help"}
        missing = given - documented[command] - READ_OPTIONS - {"--output"}
        assert not missing, f"clfractal {command}: {sorted(missing)} not in docs/guide/python.md's table"
