"""Run by python/test_wheel.sh where no OpenCL driver is registered: the installed package
must have chosen the PoCL of ``clfractal[cpu]``, list its device, and give FD curves of real
volumes equal to the NumPy reference (python/tests/references.py) on it.

CPUs newer than that PoCL's LLVM make every kernel build fail with "unknown target CPU
'generic'" (pocl/pocl#1049); then the FD checks are reported as not run and the script
exits 0, any other failure exits non-zero."""
import os
import pathlib
import re

import numpy as np

import clfractal
import references as ref

VOLUMES = ["bucky_32x32x32_uint8.raw", "m4_totaldensity_31x22x25_float32.raw", "walnut_128x96x114_uint16.raw"]

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
    try:
        curve = clfractal.fd_curve(v)
    except RuntimeError as e:
        if "unknown target CPU 'generic'" not in str(e):
            raise
        print("wheel_check: this PoCL's LLVM does not know this CPU (unknown target CPU 'generic', "
              "pocl/pocl#1049): its kernel builds fail here; FD checks not run on it")
        break
    iso = ref.default_isovalues(v)
    np.testing.assert_array_equal(curve.isovalues, iso)
    counts = ref.span_counts(v, iso, "box")
    np.testing.assert_array_equal(curve.counts, counts)
    np.testing.assert_allclose(curve.fd, ref.dimension(counts), rtol=1e-12, equal_nan=True)
    print(f"wheel_check: {name}: the FD curve equals the reference")
