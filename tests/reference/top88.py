"""The 88-line MATLAB code (Andreassen, Clausen, Schevenels, Lazarov, Sigmund 2011), transcribed
line by line to NumPy/SciPy as an independent reference for latvox's optimiser.

Usage: python3 top88.py NELX NELY VOLFRAC PENAL RMIN FT OUT.json [OUT.npy]
Writes {"compliance": [...], "iterations": N} and the physical densities (nely, nelx).
MATLAB's 1-based indices are kept where they appear, and shifted by one at each use.
"""
import json
import sys

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import spsolve


def top88(nelx, nely, volfrac, penal, rmin, ft):
    # MATERIAL PROPERTIES
    E0 = 1.0
    Emin = 1e-9
    nu = 0.3
    # PREPARE FINITE ELEMENT ANALYSIS
    A11 = np.array([[12, 3, -6, -3], [3, 12, 3, 0], [-6, 3, 12, -3], [-3, 0, -3, 12]], float)
    A12 = np.array([[-6, -3, 0, 3], [-3, -6, -3, -6], [0, -3, -6, 3], [3, -6, 3, -6]], float)
    B11 = np.array([[-4, 3, -2, 9], [3, -4, -9, 4], [-2, -9, -4, -3], [9, 4, -3, -4]], float)
    B12 = np.array([[2, -3, 4, -9], [-3, 2, 9, -2], [4, 9, 2, 3], [-9, -2, 3, 2]], float)
    KE = 1 / (1 - nu**2) / 24 * (np.block([[A11, A12], [A12.T, A11]])
                                 + nu * np.block([[B11, B12], [B12.T, B11]]))
    nodenrs = np.arange(1, (1 + nelx) * (1 + nely) + 1).reshape((1 + nely, 1 + nelx), order="F")
    edofVec = (2 * nodenrs[:-1, :-1] + 1).reshape(nelx * nely, order="F")
    edofMat = edofVec[:, None] + np.array([0, 1, 2 * nely + 2, 2 * nely + 3, 2 * nely, 2 * nely + 1, -2, -1])
    iK = np.kron(edofMat, np.ones((8, 1), int)).T.reshape(64 * nelx * nely, order="F")
    jK = np.kron(edofMat, np.ones((1, 8), int)).T.reshape(64 * nelx * nely, order="F")
    # DEFINE LOADS AND SUPPORTS (HALF MBB-BEAM)
    ndof = 2 * (nely + 1) * (nelx + 1)
    F = np.zeros(ndof)
    F[2 - 1] = -1
    U = np.zeros(ndof)
    fixeddofs = np.union1d(np.arange(1, 2 * (nely + 1) + 1, 2), [2 * (nelx + 1) * (nely + 1)])
    alldofs = np.arange(1, ndof + 1)
    freedofs = np.setdiff1d(alldofs, fixeddofs)
    # PREPARE FILTER
    c_r = int(np.ceil(rmin)) - 1
    iH, jH, sH = [], [], []
    for i1 in range(1, nelx + 1):
        for j1 in range(1, nely + 1):
            e1 = (i1 - 1) * nely + j1
            for i2 in range(max(i1 - c_r, 1), min(i1 + c_r, nelx) + 1):
                for j2 in range(max(j1 - c_r, 1), min(j1 + c_r, nely) + 1):
                    e2 = (i2 - 1) * nely + j2
                    iH.append(e1)
                    jH.append(e2)
                    sH.append(max(0.0, rmin - np.sqrt((i1 - i2) ** 2 + (j1 - j2) ** 2)))
    H = coo_matrix((sH, (np.array(iH) - 1, np.array(jH) - 1)), shape=(nelx * nely, nelx * nely)).tocsr()
    Hs = np.asarray(H.sum(axis=1)).ravel()
    # INITIALIZE ITERATION (column-major vectors: x(:) in MATLAB order)
    x = np.full(nely * nelx, volfrac)
    xPhys = x.copy()
    loop = 0
    change = 1.0
    history = []
    # START ITERATION
    while change > 0.01:
        loop += 1
        # FE-ANALYSIS
        sK = (KE.reshape(-1, order="F")[:, None] * (Emin + xPhys[None, :] ** penal * (E0 - Emin))).reshape(
            64 * nelx * nely, order="F")
        K = coo_matrix((sK, (iK - 1, jK - 1)), shape=(ndof, ndof)).tocsc()
        K = (K + K.T) / 2
        fd = freedofs - 1
        U[fd] = spsolve(K[fd, :][:, fd], F[fd])
        # OBJECTIVE FUNCTION AND SENSITIVITY ANALYSIS
        Ue = U[edofMat - 1]
        ce = np.sum((Ue @ KE) * Ue, axis=1)
        c = np.sum((Emin + xPhys ** penal * (E0 - Emin)) * ce)
        dc = -penal * (E0 - Emin) * xPhys ** (penal - 1) * ce
        dv = np.ones(nely * nelx)
        # FILTERING/MODIFICATION OF SENSITIVITIES
        if ft == 1:
            dc = H @ (x * dc) / Hs / np.maximum(1e-3, x)
        elif ft == 2:
            dc = H @ (dc / Hs)
            dv = H @ (dv / Hs)
        # OPTIMALITY CRITERIA UPDATE OF DESIGN VARIABLES AND PHYSICAL DENSITIES
        l1, l2, move = 0.0, 1e9, 0.2
        while (l2 - l1) / (l1 + l2) > 1e-3:
            lmid = 0.5 * (l2 + l1)
            xnew = np.maximum(0, np.maximum(x - move, np.minimum(1, np.minimum(x + move, x * np.sqrt(-dc / dv / lmid)))))
            if ft == 1:
                xPhys = xnew
            elif ft == 2:
                xPhys = (H @ xnew) / Hs
            if np.sum(xPhys) > volfrac * nelx * nely:
                l1 = lmid
            else:
                l2 = lmid
        change = np.max(np.abs(xnew - x))
        x = xnew
        history.append(float(c))
    return history, xPhys.reshape((nely, nelx), order="F")


if __name__ == "__main__":
    nelx, nely = int(sys.argv[1]), int(sys.argv[2])
    volfrac, penal, rmin = float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
    ft = int(sys.argv[6])
    hist, xPhys = top88(nelx, nely, volfrac, penal, rmin, ft)
    with open(sys.argv[7], "w") as f:
        json.dump({"compliance": hist, "iterations": len(hist)}, f)
    if len(sys.argv) > 8:
        np.save(sys.argv[8], xPhys)
