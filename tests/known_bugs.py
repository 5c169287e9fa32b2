"""Markers of known bugs that the tests show but that are not fixed yet (each said in README's "Known limits")."""
from __future__ import annotations

import pytest

#: The plan of the RSNAKE-style robot (fat cylinders) for its own initial head pose depends on the CPU's BLAS kernel
#: (numpy's OpenBLAS picks one per CPU): with the Haswell or Zen kernels its tracked lift fails the path check and no
#: detour is found ("a neck or head link goes 7.7 mm into the ground"); with SkylakeX or Sandybridge it plans
#: (OPENBLAS_CORETYPE chooses; found 2026-12-02). Not strict: the tests pass where the kernel lets the plan succeed.
BLAS_DEPENDENT_RSNAKE_LIFT = pytest.mark.xfail(
    strict=False, reason="known bug: the RSNAKE-style robot's lift depends on the CPU's BLAS kernel (tests/known_bugs.py)")
