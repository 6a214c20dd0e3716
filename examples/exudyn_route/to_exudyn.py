#!/usr/bin/env python3
"""femb's superelement as Exudyn's ObjectFFRFreducedOrder takes it.

Usage: to_exudyn.py BAR.h5 FULL_DIR OUT.npz

BAR.h5 is femb-reduce's superelement (with its mesh, reduction.keep_mesh); FULL_DIR the same
part's --export-matrices in Matrix Market form (the mesh's K and M, 3 DOFs per node, before any
coupling). Exudyn's FFRF body is a rigid-body node plus modes of the mesh: here the mode basis Psi
is femb's reduced basis with the floating frame's rigid motion taken out (Phi_CB E = 0, thesis
(3.7)), as mesh fields in frame axes. Exudyn computes its reduced mass, stiffness and inertia
terms from Psi and the full K and M, which gives back femb's reduced model: the script checks
that (Psi^T M Psi against femb's E^T M E, and the free-floating frequencies of the body that
Exudyn assembles at rest against femb's), writes OUT.npz, and, when Exudyn is installed, builds
the body in Exudyn and compares its free-free frequencies and the static tip deflection of the
cantilever clamped at `root` with femb's. Exit 1 when a comparison is off by more than 1e-8.
"""
import sys

import h5py
import numpy as np
import scipy.io
import scipy.linalg
import scipy.sparse


def femb_model(path):
    f = h5py.File(path, "r")
    m = {k: f[k][()] for k in ["reduced/K", "reduced/M", "floating_frame/Phi_CB", "floating_frame/origin",
                                "floating_frame/orientation", "visualization/nodes", "visualization/shapes",
                                "interfaces/positions", "visualization/interface_nodes",
                                "visualization/interface_node_offsets"]}
    m["names"] = [n.decode() if isinstance(n, bytes) else str(n) for n in f["interfaces/names"][()]]
    return m


def elastic_basis(K, M, Phi_CB):
    """E: Phi_CB E = 0, E^T M E = 1, E^T K E diagonal (the deformations the frame sees)."""
    Q, _ = np.linalg.qr(Phi_CB.T, mode="complete")
    N0 = Q[:, 6:]
    w, V = scipy.linalg.eigh(N0.T @ K @ N0, N0.T @ M @ N0)
    return N0 @ V


def read_full(directory):
    """The mesh's full K and M (Matrix Market, symmetric) and the node of each row."""
    import glob
    K = scipy.io.mmread(glob.glob(directory + "/*_K.mtx")[0]).tocsr()
    M = scipy.io.mmread(glob.glob(directory + "/*_M.mtx")[0]).tocsr()
    dofs = np.loadtxt(glob.glob(directory + "/*_dofs.csv")[0], delimiter=",", skiprows=1, dtype=int)
    return K, M, dofs


def free_frequencies(K, M):
    w = scipy.linalg.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.abs(w[6:])) / (2 * np.pi)


def femb_tip_deflection(se, force):
    """femb's reduced model clamped at interface 0 (root), `force` at interface 1 (tip)."""
    K = se["reduced/K"]
    free = np.arange(6, K.shape[0])
    f = np.zeros(K.shape[0])
    f[6:9] = force
    return np.linalg.solve(K[np.ix_(free, free)], f[free])[:3]


def main(h5_path, full_dir, out_path):
    se = femb_model(h5_path)
    K_red, M_red = se["reduced/K"], se["reduced/M"]
    A, origin = se["floating_frame/orientation"], se["floating_frame/origin"]
    E = elastic_basis(K_red, M_red, se["floating_frame/Phi_CB"])
    nodes = se["visualization/nodes"]
    n = len(nodes)
    shapes = se["visualization/shapes"]  # (3 n) x n_reduced, node-major, part axes
    Psi = (shapes @ E).reshape(n, 3, -1)
    Psi = np.einsum("ba,nbj->naj", A, Psi).reshape(3 * n, -1)  # frame axes
    x = (nodes - origin) @ A  # node positions in frame axes, from the frame origin
    K_full, M_full, dofs = read_full(full_dir)
    expected = np.column_stack([np.repeat(np.arange(1, n + 1), 3), np.tile([1, 2, 3], n)])
    if dofs.shape != expected.shape or (dofs != expected).any():
        sys.exit("to_exudyn: the exported matrices' DOFs are not the superelement mesh's 3 per node")
    # Exudyn works in frame axes; a rotation of every node's triple leaves an isotropic mesh
    # matrix as it is only when A = 1, so turn the full matrices too.
    R = scipy.sparse.kron(scipy.sparse.identity(n), A.T)
    K_f, M_f = (R @ K_full @ R.T).tocsr(), (R @ M_full @ R.T).tocsr()
    M_psi, K_psi = Psi.T @ (M_f @ Psi), Psi.T @ (K_f @ Psi)
    M_e, K_e = E.T @ M_red @ E, E.T @ K_red @ E
    err_m = np.abs(M_psi - M_e).max() / np.abs(M_e).max()
    err_k = np.abs(K_psi - K_e).max() / np.abs(K_e).max()
    print("to_exudyn: %d mesh nodes, %d modes; Psi^T M Psi vs femb's E^T M E %.1e, Psi^T K Psi vs E^T K E %.1e"
          % (n, Psi.shape[1], err_m, err_k))
    # The body at rest as Exudyn assembles it: rigid translation, rotation about the frame origin,
    # modes; mass [Phi_t, X~^T, Psi]^T M [Phi_t, X~^T, Psi], stiffness diag(0, Psi^T K Psi).
    Phi_t = np.tile(np.eye(3), (n, 1))
    rot = np.zeros((3 * n, 3))
    for a in range(3):
        rot[:, a] = np.cross(np.eye(3)[a], x).reshape(-1)
    T = np.hstack([Phi_t, rot, Psi])
    M_body = T.T @ (M_f @ T)
    K_body = np.zeros_like(M_body)
    K_body[6:, 6:] = K_psi
    f_body, f_femb = free_frequencies(K_body, M_body), free_frequencies(K_red, M_red)
    err_f = np.abs(f_body / f_femb - 1).max()
    print("to_exudyn: free-floating frequencies %s Hz; femb's %s Hz; largest difference %.1e"
          % (np.array2string(f_body[:4], precision=3), np.array2string(f_femb[:4], precision=3), err_f))
    offsets = se["visualization/interface_node_offsets"]
    sets = [se["visualization/interface_nodes"][offsets[k]:offsets[k + 1]] for k in range(len(offsets) - 1)]
    np.savez(out_path, nodes=x, modeBasis=Psi, massMatrixReduced=M_psi, stiffnessMatrixReduced=K_psi,
             K_row=K_f.tocoo().row, K_col=K_f.tocoo().col, K_val=K_f.tocoo().data,
             M_row=M_f.tocoo().row, M_col=M_f.tocoo().col, M_val=M_f.tocoo().data,
             frame_origin=origin, frame_axes=A, interface_names=np.array(se["names"]),
             **{"interface_nodes_" + name: s for name, s in zip(se["names"], sets)})
    print("to_exudyn: wrote %s" % out_path)
    ok = err_m < 1e-8 and err_k < 1e-8 and err_f < 1e-8
    force = np.array([0.0, 0.0, 100.0])
    tip = femb_tip_deflection(se, force)
    print("to_exudyn: femb's cantilever (root clamped, 100 N along z at tip): tip u_z %.6e m" % tip[2])
    try:
        import exudyn  # noqa: F401
    except ImportError:
        print("to_exudyn: Exudyn is not installed: the Exudyn model is skipped (pip install exudyn)")
        return 0 if ok else 1
    return exudyn_model(x, Psi, K_f, M_f, sets, f_femb, tip, force) if ok else 1


def exudyn_model(x, Psi, K_f, M_f, sets, f_femb, tip, force):
    """The same body in Exudyn (FEMinterface, ObjectFFRFreducedOrderInterface; Exudyn 1.11's API)."""
    import exudyn as exu
    import exudyn.itemInterface as eii
    from exudyn.FEM import FEMinterface, ObjectFFRFreducedOrderInterface
    fem = FEMinterface()
    fem.nodes = {"Position": x}
    fem.massMatrix, fem.stiffnessMatrix = M_f, K_f
    fem.modeBasis = {"matrix": Psi, "type": "femb elastic basis"}
    cms = ObjectFFRFreducedOrderInterface(fem)
    results = []
    for clamped in (False, True):
        SC = exu.SystemContainer()
        mbs = SC.AddSystem()
        body = cms.AddObjectFFRFreducedOrder(mbs, positionRef=[0, 0, 0])
        obj = body["oFFRFreducedOrder"]
        w_root = np.ones(len(sets[0])) / len(sets[0])
        w_tip = np.ones(len(sets[1])) / len(sets[1])
        if clamped:
            ground = mbs.AddObject(eii.ObjectGround())
            m_ground = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground, localPosition=list(x[sets[0]].mean(0))))
            m_root = mbs.AddMarker(eii.MarkerSuperElementRigid(bodyNumber=obj, meshNodeNumbers=np.array(sets[0]),
                                                                weightingFactors=w_root))
            mbs.AddObject(eii.GenericJoint(markerNumbers=[m_ground, m_root], constrainedAxes=[1, 1, 1, 1, 1, 1]))
            m_tip = mbs.AddMarker(eii.MarkerSuperElementPosition(bodyNumber=obj, meshNodeNumbers=np.array(sets[1]),
                                                                  weightingFactors=w_tip))
            mbs.AddLoad(eii.Force(markerNumber=m_tip, loadVector=list(force)))
            sensor = mbs.AddSensor(eii.SensorMarker(markerNumber=m_tip, storeInternal=True,
                                                    outputVariableType=exu.OutputVariableType.Displacement))
            mbs.Assemble()
            exu.SolveStatic(mbs, exu.SimulationSettings())
            results.append(mbs.GetSensorValues(sensor)[2])
        else:
            mbs.Assemble()
            values = mbs.ComputeODE2Eigenvalues()[0]
            results.append(np.sqrt(np.abs(np.sort(values)[6:6 + len(f_femb)])) / (2 * np.pi))
    f_exu, tip_exu = results
    err_f = np.abs(f_exu[:4] / f_femb[:4] - 1).max()
    err_u = abs(tip_exu / tip[2] - 1)
    print("to_exudyn: Exudyn's body: free-free %s Hz (%.1e from femb's); tip u_z %.6e m (%.1e from femb's)"
          % (np.array2string(f_exu[:4], precision=3), err_f, tip_exu, err_u))
    return 0 if err_f < 1e-6 and err_u < 1e-6 else 1


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__.split("\n\n")[1])
    sys.exit(main(*sys.argv[1:]))
