"""Compares two superelement files of one part reduced by different solvers (CHOLMOD and femb's
Lanczos against MUMPS and SLEPc on MPI ranks): the same layout (every dataset of one is in the
other, with its shape), the fixed-interface frequencies to 1e-9 relative, and the reduced K and M
to 1e-8 relative to their largest entry once the sign of each internal mode and modal derivative
is taken from the reference (an eigenvector's sign is arbitrary, and a derivative's follows); the
inertia invariants, the geometric stiffnesses, the polynomial force, the frame, the mode shapes on
the mesh and the modal stresses to 1e-6 of their largest entry, in the same signs; when
both hold the full model's free-free frequencies, the flexible ones (all but the first six, whose
values are the round-off of zero) to 1e-9 relative. Prints the figures; exit 1 when one is
exceeded.

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
    # What the stages after the projection made (on MPI ranks from each rank's share of the
    # elements, summed), in the same signs: the inertia invariants and the inertia load cases'
    # geometric stiffnesses (n x n blocks, stacked), the polynomial force (A[i, p(j, k)],
    # B[p, p']), the frame's row, the mode shapes on the mesh, the modal stresses and gradients
    # (single precision), each to 1e-6 of its largest entry: these are linear in the vectors,
    # which two eigen solvers give to their residual tolerance (1e-8) over the modes' relative
    # gap (the reduced K and M are quadratic in that difference).
    pair_sign = np.array([signs[j] * signs[k] for j in range(n) for k in range(j, n)])
    signed = {
        "reduced/inertia_invariants/Gamma": lambda X: np.vstack([S @ B @ S for B in np.split(X, len(X) // n)]),
        "reduced/inertia_invariants/Xi": lambda X: np.vstack([S @ B @ S for B in np.split(X, len(X) // n)]),
        "reduced/geometric_stiffness/inertia": lambda X: np.vstack([S @ B @ S for B in np.split(X, len(X) // n)]),
        "reduced/polynomial/A": lambda X: S @ X * pair_sign,
        "reduced/polynomial/B": lambda X: pair_sign[:, None] * X * pair_sign,
        "floating_frame/Phi_CB": lambda X: X @ S,
        "visualization/shapes": lambda X: X @ S,
        "stress/modes": lambda X: X @ S,
        "stress/gradients": lambda X: X @ S,
        "stress/inertia_modes": lambda X: X,
    }
    stage_text = []
    for name, align in signed.items():
        if name not in a or name not in b:
            continue
        X_a, X_b = a[name][()].astype(float), align(b[name][()].astype(float))
        error = np.max(np.abs(X_a - X_b)) / max(np.max(np.abs(X_a)), 1e-300)
        stage_text.append(f"{name.split('/')[-1]} {error:.1e}")
        ok = ok and error <= 1e-6
    full = "full_model/free_free_frequencies_hz"
    full_text, full_error = "", 0.0
    if full in a and full in b:
        ga, gb = a[full][()][6:], b[full][()][6:]
        full_error = np.max(np.abs(ga - gb) / ga)
        full_text = f", full model's flexible free-free frequencies {full_error:.2e} ({len(ga)})"
    print(f"{other_path} against {reference_path}: frequencies {frequency_error:.2e}, K_r {K_error:.2e}, "
          f"M_r {M_error:.2e} (relative){full_text}, {n_modes} internal modes, {n} reduced DOFs; "
          + ", ".join(stage_text))
    ok = ok and frequency_error <= 1e-9 and K_error <= 1e-8 and M_error <= 1e-8 and full_error <= 1e-9
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
