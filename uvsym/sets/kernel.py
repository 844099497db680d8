"""Compiled box reduction (Girard and Combastel selections), built with the system C compiler on first use.

The same computation as :func:`uvsym.sets.reduction.reduce` for ``girard`` and ``combastel``
(scores, the ``count`` smallest replaced by a box, kept generators in their order), in one C
call through ctypes instead of a dozen numpy calls. Ties in the score go to the lower index.
Without a C compiler (or when the build fails) :func:`box_reduce` is None and the numpy path runs.
The work buffer is shared per shape within a process: not for concurrent calls from threads.
"""

from __future__ import annotations

import ctypes
import functools
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from uvsym.codegen.compile import find_compiler

__all__ = ["box_reduce"]

SOURCE = r"""
#include <math.h>
#include <stdlib.h>

/* G: n x m row-major. Replaces the `count` generators of smallest score by the box of their
   absolute row sums. work holds, in order: G, n x m doubles row-major (the input); out,
   n x (m - count + n) doubles row-major, filled
   with the kept generators (in order) then the non-zero box columns; box, n doubles (the row
   sums); score and largest, m doubles each; order, m ints; replaced, m bytes (1 for a
   replaced generator).
   Returns the number of columns written. */

int uvsym_box_reduce(int n, int m, int count, int combastel, void *work) {
    const double *G = (const double *)work;
    double *out = (double *)work + n * m, *box = out + n * (m - count + n), *score = box + n;
    double *largest = score + m;
    int *order = (int *)(largest + m);
    unsigned char *replaced = (unsigned char *)(order + m);
    for (int j = 0; j < m; ++j) { score[j] = 0.0; largest[j] = 0.0; }
    for (int i = 0; i < n; ++i) {  /* row by row: contiguous, vectorisable */
        const double *row = G + i * m;
        if (combastel) {
            for (int j = 0; j < m; ++j) score[j] += row[j] * row[j];
        } else {
            for (int j = 0; j < m; ++j) {
                double a = fabs(row[j]);
                score[j] += a;
                largest[j] = a > largest[j] ? a : largest[j];
            }
        }
    }
    if (!combastel)
        for (int j = 0; j < m; ++j) score[j] -= largest[j];
    int kept = m - count, width = kept + n;
    for (int j = 0; j < m; ++j) { order[j] = j; replaced[j] = 0; }
    /* quickselect: the `count` smallest (score, index) pairs end up in order[0 .. count-1] */
    int lo = 0, hi = m - 1, k = count - 1;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2, pivot = order[mid];
        double ps = score[pivot];
        int i = lo, j = hi;
        while (i <= j) {
            while (score[order[i]] < ps || (score[order[i]] == ps && order[i] < pivot)) ++i;
            while (score[order[j]] > ps || (score[order[j]] == ps && order[j] > pivot)) --j;
            if (i <= j) { int t = order[i]; order[i] = order[j]; order[j] = t; ++i; --j; }
        }
        if (k <= j) hi = j; else if (k >= i) lo = i; else break;
    }
    for (int c = 0; c < count; ++c) replaced[order[c]] = 1;
    int c = 0;
    double *in_box = score;  /* the scores are spent: 1.0 for a replaced generator, else 0.0 */
    for (int j = 0; j < m; ++j) { order[c] = j; c += !replaced[j]; in_box[j] = replaced[j]; }  /* kept, in order */
    for (int i = 0; i < n; ++i) {
        const double *row = G + i * m;
        double *target = out + i * width;
        for (int t = 0; t < kept; ++t) target[t] = row[order[t]];
        /* the row's sum over the replaced generators in eight interleaved partial sums (a vector
           of independent additions instead of one chain of m) */
        double part[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, tail = 0.0;
        int j = 0;
        for (; j + 8 <= m; j += 8)
            for (int q = 0; q < 8; ++q) part[q] += in_box[j + q] * fabs(row[j + q]);
        for (; j < m; ++j) tail += in_box[j] * fabs(row[j]);
        box[i] = (((part[0] + part[1]) + (part[2] + part[3])) + ((part[4] + part[5]) + (part[6] + part[7]))) + tail;
    }
    int col = kept;
    for (int i = 0; i < n; ++i) {
        if (box[i] > 0.0) {
            for (int r = 0; r < n; ++r) out[r * width + col] = r == i ? box[i] : 0.0;
            ++col;
        }
    }
    return col;
}
"""


@functools.lru_cache(maxsize=1)
def _library():
    compiler = find_compiler()
    if compiler is None:
        return None
    folder = Path(tempfile.mkdtemp(prefix="uvsym-sets-"))
    source, library = folder / "box_reduce.c", folder / "box_reduce.so"
    source.write_text(SOURCE)
    try:
        subprocess.run([compiler, "-O3", "-march=native", "-fPIC", "-shared", "-o", str(library), str(source), "-lm"],
                       check=True, capture_output=True, timeout=120)
        lib = ctypes.CDLL(str(library))
    except (OSError, subprocess.SubprocessError):
        return None
    function = lib.uvsym_box_reduce
    function.restype = ctypes.c_int  # no argtypes: Python ints go as C ints, the address as a c_void_p, and
    return function  # ctypes skips a conversion per argument (0.5 us of a 3 us call)


def _address(array: np.ndarray) -> int:
    return array.__array_interface__["data"][0]


@functools.lru_cache(maxsize=32)
def _workspace(n: int, m: int, count: int, combastel: bool) -> tuple:
    """One work buffer per shape (the C layout): numpy views of its G, out (one per number of columns written:
    slicing anew costs as much as the copy), replaced and box parts, and the kernel's call on it with every
    argument bound. G is copied in (cheaper than reading an array's address)."""
    width = m - count + n
    doubles = n * m + n * width + n + 2 * m
    work = np.zeros(doubles * 8 + m * 4 + m, dtype=np.uint8)
    as_doubles = work[:doubles * 8].view(np.float64)
    G = as_doubles[:n * m].reshape(n, m)
    out = as_doubles[n * m:n * m + n * width].reshape(n, width)
    box = as_doubles[n * m + n * width:n * m + n * width + n]
    replaced = work[doubles * 8 + m * 4:]
    call = functools.partial(_library(), int(n), int(m), int(count), int(combastel), ctypes.c_void_p(_address(work)))
    written = tuple(out[:, :columns] for columns in range(width + 1))
    return G, written, replaced, box, call  # the int()s: a numpy integer has no ctypes conversion without argtypes


def box_reduce(G: np.ndarray, count: int, combastel: bool, details: bool = True):
    """(new generators (n, <= m - count + n), replaced mask (m,) bool, box row sums (n,)) as fresh
    arrays (mask and sums None unless ``details``), or None without a compiled kernel.
    G: (n, m) finite, ``n <= count <= m``."""
    function = _library()
    if function is None:
        return None
    G_in, written, replaced, box, call = _workspace(*G.shape, count, combastel)
    G_in[...] = G
    new_G = written[call()].copy()
    if not details:
        return new_G, None, None
    return new_G, replaced.astype(bool), box.copy()
