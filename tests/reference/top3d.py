"""top3d (Liu & Tovar 2014, "An efficient 3D topology optimization code written in Matlab"),
transcribed line by line to NumPy/SciPy as an independent reference for latvox's optimiser:
the cantilever with its left face clamped and a line load along the lower right edge, density
filter, OC update with move limit 0.2, stop at change <= 0.01 (or 200 iterations).

Usage: python3 top3d.py NELX NELY NELZ VOLFRAC PENAL RMIN OUT.json [OUT.npy]
Writes {"compliance": [...], "iterations": N} and the physical densities (nely, nelx, nelz).
"""
import json
import sys

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import spsolve


def lk_H8(nu):
    A = np.array([[32, 6, -8, 6, -6, 4, 3, -6, -10, 3, -3, -3, -4, -8],
                  [-48, 0, 0, -24, 24, 0, 0, 0, 12, -12, 0, 12, 12, 12]], float)
    k = 1 / 144 * A.T @ np.array([1, nu])

    def K(idx):
        return k[np.array(idx) - 1]

    K1 = K([[1, 2, 2, 3, 5, 5], [2, 1, 2, 4, 6, 7], [2, 2, 1, 4, 7, 6],
            [3, 4, 4, 1, 8, 8], [5, 6, 7, 8, 1, 2], [5, 7, 6, 8, 2, 1]])
    K2 = K([[9, 8, 12, 6, 4, 7], [8, 9, 12, 5, 3, 5], [10, 10, 13, 7, 4, 6],
            [6, 5, 11, 9, 2, 10], [4, 3, 5, 2, 9, 12], [11, 4, 6, 12, 10, 13]])
    K3 = K([[6, 7, 4, 9, 12, 8], [7, 6, 4, 10, 13, 10], [5, 5, 3, 8, 12, 9],
            [9, 10, 2, 6, 11, 5], [12, 13, 10, 11, 6, 4], [2, 12, 9, 4, 5, 3]])
    K4 = K([[14, 11, 11, 13, 10, 10], [11, 14, 11, 12, 9, 8], [11, 11, 14, 12, 8, 9],
            [13, 12, 12, 14, 7, 7], [10, 9, 8, 7, 14, 11], [10, 8, 9, 7, 11, 14]])
    K5 = K([[1, 2, 8, 3, 5, 4], [2, 1, 8, 4, 6, 11], [8, 8, 1, 5, 11, 6],
            [3, 4, 5, 1, 8, 2], [5, 6, 11, 8, 1, 8], [4, 11, 6, 2, 8, 1]])
    K6 = K([[14, 11, 7, 13, 10, 12], [11, 14, 7, 12, 9, 2], [7, 7, 14, 10, 2, 9],
            [13, 12, 10, 14, 7, 11], [10, 9, 2, 7, 14, 7], [12, 2, 9, 11, 7, 14]])
    return 1 / ((nu + 1) * (1 - 2 * nu)) * np.block([[K1, K2, K3, K4],
                                                     [K2.T, K5, K6, K3.T],
                                                     [K3.T, K6, K5.T, K2.T],
                                                     [K4, K3, K2, K1.T]])


def top3d(nelx, nely, nelz, volfrac, penal, rmin):
    # USER-DEFINED LOOP PARAMETERS
    maxloop = 200
    tolx = 0.01
    # USER-DEFINED MATERIAL PROPERTIES
    E0 = 1.0
    Emin = 1e-9
    nu = 0.3
    # USER-DEFINED LOAD DOFs: [il,jl,kl] = meshgrid(nelx, 0, 0:nelz)
    kl = np.arange(0, nelz + 1)
    il, jl = nelx, 0
    loadnid = kl * (nelx + 1) * (nely + 1) + il * (nely + 1) + (nely + 1 - jl)
    loaddof = 3 * loadnid - 1
    # USER-DEFINED SUPPORT FIXED DOFs: [iif,jf,kf] = meshgrid(0,0:nely,0:nelz)
    jf, kf = np.meshgrid(np.arange(0, nely + 1), np.arange(0, nelz + 1), indexing="ij")
    iif = 0
    fixednid = (kf * (nelx + 1) * (nely + 1) + iif * (nely + 1) + (nely + 1 - jf)).ravel()
    fixeddof = np.concatenate([3 * fixednid, 3 * fixednid - 1, 3 * fixednid - 2])
    # PREPARE FINITE ELEMENT ANALYSIS
    nele = nelx * nely * nelz
    ndof = 3 * (nelx + 1) * (nely + 1) * (nelz + 1)
    F = np.zeros(ndof)
    np.add.at(F, loaddof - 1, -1.0)
    U = np.zeros(ndof)
    freedofs = np.setdiff1d(np.arange(1, ndof + 1), fixeddof)
    KE = lk_H8(nu)
    nodegrd = np.arange(1, (nely + 1) * (nelx + 1) + 1).reshape((nely + 1, nelx + 1), order="F")
    nodeids = nodegrd[:-1, :-1].reshape(nely * nelx, order="F")
    nodeidz = np.arange(0, nelz) * (nely + 1) * (nelx + 1)
    nodeids = (nodeids[:, None] + nodeidz[None, :]).reshape(-1, order="F")
    edofVec = 3 * nodeids + 1
    off = np.array([0, 1, 2] + [3 * nely + v for v in [3, 4, 5, 0, 1, 2]] + [-3, -2, -1])
    edofMat = edofVec[:, None] + np.concatenate([off, 3 * (nely + 1) * (nelx + 1) + off])[None, :]
    iK = np.kron(edofMat, np.ones((24, 1), int)).T
    jK = np.kron(edofMat, np.ones((1, 24), int)).T
    # PREPARE FILTER
    step = int(np.ceil(rmin)) - 1
    iH, jH, vH = [], [], []
    for el in range(1, nele + 1):
        # [i,j,k] = ind2sub([nely,nelx,nelz],el)
        e0 = el - 1
        i = e0 % nely + 1
        j = (e0 // nely) % nelx + 1
        k = e0 // (nely * nelx) + 1
        for i2 in range(max(1, i - step), min(nely, i + step) + 1):
            for j2 in range(max(1, j - step), min(nelx, j + step) + 1):
                for k2 in range(max(1, k - step), min(nelz, k + step) + 1):
                    d = max(0.0, rmin - np.sqrt((i2 - i) ** 2 + (j2 - j) ** 2 + (k2 - k) ** 2))
                    iH.append(el)
                    jH.append((k2 - 1) * nely * nelx + (j2 - 1) * nely + i2)
                    vH.append(d)
    H = coo_matrix((vH, (np.array(iH) - 1, np.array(jH) - 1)), shape=(nele, nele)).tocsr()
    Hs = np.asarray(H.sum(axis=1)).ravel()
    # INITIALIZE ITERATION
    x = np.full(nele, volfrac)
    xPhys = x.copy()
    loop = 0
    change = 1.0
    history = []
    # START ITERATION
    while change > tolx and loop < maxloop:
        loop += 1
        # FE-ANALYSIS
        sK = KE.reshape(-1, order="F")[:, None] * (Emin + xPhys[None, :] ** penal * (E0 - Emin))
        K = coo_matrix((sK.reshape(-1, order="F"), (iK.reshape(-1, order="F") - 1, jK.reshape(-1, order="F") - 1)),
                       shape=(ndof, ndof)).tocsc()
        K = (K + K.T) / 2
        fd = freedofs - 1
        U[fd] = spsolve(K[fd, :][:, fd], F[fd])
        # OBJECTIVE FUNCTION AND SENSITIVITY ANALYSIS
        Ue = U[edofMat - 1]
        ce = np.sum((Ue @ KE) * Ue, axis=1)
        c = np.sum((Emin + xPhys ** penal * (E0 - Emin)) * ce)
        dc = -penal * (E0 - Emin) * xPhys ** (penal - 1) * ce
        dv = np.ones(nele)
        # FILTERING AND MODIFICATION OF SENSITIVITIES
        dc = H @ (dc / Hs)
        dv = H @ (dv / Hs)
        # OPTIMALITY CRITERIA UPDATE
        l1, l2, move = 0.0, 1e9, 0.2
        while (l2 - l1) / (l1 + l2) > 1e-3:
            lmid = 0.5 * (l2 + l1)
            xnew = np.maximum(0, np.maximum(x - move, np.minimum(1, np.minimum(x + move, x * np.sqrt(-dc / dv / lmid)))))
            xPhys = (H @ xnew) / Hs
            if np.sum(xPhys) > volfrac * nele:
                l1 = lmid
            else:
                l2 = lmid
        change = np.max(np.abs(xnew - x))
        x = xnew
        history.append(float(c))
    return history, xPhys.reshape((nely, nelx, nelz), order="F")


if __name__ == "__main__":
    nelx, nely, nelz = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    volfrac, penal, rmin = float(sys.argv[4]), float(sys.argv[5]), float(sys.argv[6])
    hist, xPhys = top3d(nelx, nely, nelz, volfrac, penal, rmin)
    with open(sys.argv[7], "w") as f:
        json.dump({"compliance": hist, "iterations": len(hist)}, f)
    if len(sys.argv) > 8:
        np.save(sys.argv[8], xPhys)
