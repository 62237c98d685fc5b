"""Assembly over chunks of elements, and the light basis a model keeps afterwards.

A scikit-fem basis holds every basis function's values and gradients at every quadrature
point of every element it covers. On spl2782 level 3 (88 256 elements, order-5 quadrature)
that is 0.34 GB for the vector P2 basis of the elastic model and 0.09 GB for the scalar one,
held for as long as the basis lives. The matrices are sums over elements, so they are
assembled here chunk by chunk (the same sums, so the same matrices to round-off), and the
model keeps a basis without quadrature points for what it needs afterwards: DOF numbering,
DOF locations, facets' DOFs and point probes, none of which reads quadrature (even one point
per element would hold 0.12 GB for vector P2 at level 3: values, gradients and Hessians).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import functools
from collections.abc import Mapping

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementTriP0, asm

#: elements per chunk: the quadrature values of a chunk stay under about 80 MB for vector P2
#: at order 5 (the largest basis the reference builds), while the per-chunk overhead of
#: scikit-fem (a few ms) stays negligible against the assembly itself
CHUNK_ELEMENTS = 20_000


def light_basis(mesh, elem) -> Basis:
    """A basis of ``elem`` on ``mesh`` without quadrature points: DOFs, their locations and
    probes, without the memory of a quadrature (it cannot assemble: :func:`assemble` does)."""
    return Basis(mesh, elem, quadrature=(np.zeros((mesh.dim(), 0)), np.zeros(0)))


def assemble(form, mesh, elem, intorder: int, cells: Mapping[str, np.ndarray] | None = None,
             elements: np.ndarray | None = None, test_elem=None,
             chunk: int = CHUNK_ELEMENTS):
    """``form`` assembled over ``elements`` of ``mesh`` (default: all), in chunks.

    ``elem`` is the trial element (the only one for a linear form), ``test_elem`` the test
    element of a mixed bilinear form (default: ``elem``). ``cells`` are per-element constants
    (arrays of length ``mesh.nelements``) handed to the form by name. A bilinear form gives a
    CSR matrix (test DOFs x trial DOFs), a linear form a vector.
    """
    idx = np.arange(mesh.nelements) if elements is None else np.asarray(elements)
    cells = cells or {}
    total = None
    for start in range(0, max(len(idx), 1), chunk):
        part = idx[start:start + chunk]
        ub = Basis(mesh, elem, elements=part, intorder=intorder)
        p0 = ub.with_element(ElementTriP0())
        fields = {k: p0.interpolate(np.asarray(v, dtype=float)) for k, v in cells.items()}
        if isinstance(form, BilinearForm) and test_elem is not None:
            vb = Basis(mesh, test_elem, elements=part, quadrature=ub.quadrature)
            got = asm(form, ub, vb, **fields)
        else:
            got = asm(form, ub, **fields)
        got = got.tocsr() if sp.issparse(got) else got
        total = got if total is None else total + got
        del ub, p0, fields  # this chunk's quadrature values go before the next chunk's
    return total


def return_free_memory() -> None:
    """Hand the heap's free pages back to the system (glibc's ``malloc_trim``; elsewhere a
    no-op). glibc serves arrays under its moving mmap threshold (up to 32 MiB) from the heap,
    and the pages an assembly's temporaries freed stay resident until trimmed: on spl2782
    level 3 about 0.2 GB, under the elastic factorisation that follows."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@functools.cache
def _malloc_trim():
    try:
        return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim
    except (OSError, AttributeError):  # not glibc
        return None
