"""Compares two superelement files of one part reduced by different solvers (CHOLMOD and femb's
Lanczos against MUMPS and SLEPc on MPI ranks): the same layout (every dataset of one is in the
other, with its shape), the fixed-interface frequencies to 1e-9 relative, and the reduced K and M
to 1e-8 relative to their largest entry once the sign of each internal mode and modal derivative
is taken from the reference (an eigenvector's sign is arbitrary, and a derivative's follows). Prints the figures; exit 1 when one is exceeded.

usage: compare_superelements.py REFERENCE.h5 OTHER.h5
"""
import sys

import h5py
import numpy as np


def datasets(f):
    out = {}
    f.visititems(lambda name, o: out.__setitem__(name, o.shape) if isinstance(o, h5py.Dataset) else None)
    return out


def main(reference_path, other_path):
    a, b = h5py.File(reference_path, "r"), h5py.File(other_path, "r")
    layout_a, layout_b = datasets(a), datasets(b)
    ok = True
    if layout_a != layout_b:
        print("layout differs:", sorted(set(layout_a.items()) ^ set(layout_b.items())))
        ok = False
    fa, fb = a["reduced/internal_frequencies_hz"][()], b["reduced/internal_frequencies_hz"][()]
    frequency_error = np.max(np.abs(fa - fb) / fa)
    n_modes = len(fa)
    K_a, M_a, K_b, M_b = (f[d][()] for f in (a, b) for d in ("reduced/K", "reduced/M"))
    n = K_a.shape[0]
    first = 6 * len(a["interfaces/names"])  # the internal modes follow the interfaces' coordinates
    signs = np.ones(n)
    # The sign of each internal mode and modal derivative: the one that makes its coupling to the
    # interfaces (whose coordinates have no sign to choose) in M, or else in K, match the reference's.
    for j in range(first, n):
        for X_a, X_b in ((M_a, M_b), (K_a, K_b)):
            dot = np.dot(X_a[:first, j], X_b[:first, j])
            if abs(dot) > 1e-6 * np.linalg.norm(X_a[:first, j]) * np.linalg.norm(X_b[:first, j]):
                signs[j] = 1.0 if dot >= 0 else -1.0
                break
    S = np.diag(signs)
    K_b, M_b = S @ K_b @ S, S @ M_b @ S
    K_error = np.max(np.abs(K_a - K_b)) / np.max(np.abs(K_a))
    M_error = np.max(np.abs(M_a - M_b)) / np.max(np.abs(M_a))
    print(f"{other_path} against {reference_path}: frequencies {frequency_error:.2e}, K_r {K_error:.2e}, "
          f"M_r {M_error:.2e} (relative), {n_modes} internal modes, {n} reduced DOFs")
    ok = ok and frequency_error <= 1e-9 and K_error <= 1e-8 and M_error <= 1e-8
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
