"""physgs.allocator: freed memory stays in the process, so the next iteration's arrays reuse its
pages instead of faulting fresh ones in (glibc only)."""

import subprocess
import sys

import pytest

CHILD = """
import resource, sys
import numpy as np
from physgs.allocator import retain_freed_memory
if sys.argv[1] == "retain":
    assert retain_freed_memory()
def iteration():  # what a training iteration does: allocate, fill and free a few MB
    a = [np.ones(600_000) for _ in range(4)]  # 4 x 4.8 MB
    del a
iteration()
f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(5):
    iteration()
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0)
"""


def _faults(mode: str) -> int:
    out = subprocess.run(
        [sys.executable, "-c", CHILD, mode], capture_output=True, text=True, check=True
    )
    return int(out.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
def test_retained_memory_spares_the_page_faults_of_each_iteration():
    default, retained = _faults("default"), _faults("retain")
    # 5 iterations x 19 MB = ~23,000 fresh 4 KiB pages by default; a few dozen when retained
    assert default > 5000, default
    assert retained < default / 20, (retained, default)
