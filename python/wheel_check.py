"""Run by python/test_wheel.sh where no OpenCL driver is registered: the installed package
must have chosen the PoCL of ``clfractal[cpu]``, list its device, and give FD curves of real
volumes equal to the NumPy reference (python/tests/references.py) on it.

On CPUs that PoCL's LLVM 14 cannot name (pocl/pocl#1049) the package leaves it unregistered
and says what to install instead: then the script checks that the package predicted it, that
the PyPI PoCL, registered by hand, indeed fails every kernel build with "unknown target CPU
'generic'", and that the package's error names what to install. A CPU the package
predicted to work and whose kernel builds fail, or any other failure, exits non-zero."""
import os
import pathlib
import re

import numpy as np

import clfractal
import references as ref

VOLUMES = ["bucky_32x32x32_uint8.raw", "m4_totaldensity_31x22x25_float32.raw", "walnut_128x96x114_uint16.raw"]

if clfractal.OPENCL_DRIVERS.startswith("none (pocl-binary-distribution's PoCL 3.0 cannot build kernels"):
    # The package's prediction: checked against the PoCL itself in a fresh interpreter.
    import subprocess
    import sys
    try:
        clfractal.fd_curve(np.zeros((4, 4, 4), np.uint8))
        raise AssertionError("a device was found though no driver was registered")
    except RuntimeError as e:
        assert "apt install pocl-opencl-icd" in str(e), e
    probe = ("import numpy as np, clfractal\ntry:\n    clfractal.fd_curve(np.zeros((4, 4, 4), np.uint8))\n"
             "except RuntimeError as e:\n    print(e)\n")
    env = dict(os.environ, OCL_ICD_VENDORS=clfractal._wheel_pocl())
    out = subprocess.run([sys.executable, "-c", probe], env=env, capture_output=True, text=True).stdout
    assert "unknown target CPU 'generic'" in out, out
    print("wheel_check: the PyPI PoCL cannot build kernels for this CPU, as the package predicted:",
          clfractal.OPENCL_DRIVERS)
    raise SystemExit(0)
assert clfractal.OPENCL_DRIVERS.startswith("pocl-binary-distribution"), clfractal.OPENCL_DRIVERS
found = clfractal.devices()
assert found and found[0]["platform"] == "Portable Computing Language", found
print("wheel_check:", clfractal.device_description(), "|", found[0]["drivers"])
data = pathlib.Path(os.environ["CLFRACTAL_SHARED_DATA"])
for name in VOLUMES:
    path = data / name
    if not path.exists():
        print(f"wheel_check: {path} not found, skipped")
        continue
    nx, ny, nz, dtype = re.match(r".*_(\d+)x(\d+)x(\d+)_(\w+)\.raw$", name).groups()
    v = np.fromfile(path, dtype=np.dtype(dtype).newbyteorder("<")).reshape(int(nz), int(ny), int(nx))
    curve = clfractal.fd_curve(v)  # the package predicted this CPU works with this PoCL
    iso = ref.default_isovalues(v)
    np.testing.assert_array_equal(curve.isovalues, iso)
    counts = ref.span_counts(v, iso, "box")
    np.testing.assert_array_equal(curve.counts, counts)
    np.testing.assert_allclose(curve.fd, ref.dimension(counts), rtol=1e-12, equal_nan=True)
    print(f"wheel_check: {name}: the FD curve equals the reference")
