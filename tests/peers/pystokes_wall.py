"""PyStokes's wall-bounded mobility matrix (wallBounded.Rbm.mobilityTT, one unit force at a time).
Reads "mu a x1 y1 z1 x2 y2 z2 ..." on stdin (SI units, wall at z = 0); prints the 3N x 3N matrix
in swimlab's order (sphere-major: row 3i + k is sphere i's velocity component k), one row a line."""
import sys

import numpy as np
import pystokes

vals = [float(v) for v in sys.stdin.read().split()]
mu, a, X = vals[0], vals[1], np.array(vals[2:]).reshape(-1, 3)
N = len(X)
r = np.concatenate([X[:, 0], X[:, 1], X[:, 2]])
rbm = pystokes.wallBounded.Rbm(radius=a, particles=N, viscosity=mu)
M = np.zeros((3 * N, 3 * N))
for j in range(N):
    for k in range(3):
        F = np.zeros(3 * N)
        F[k * N + j] = 1.0
        v = np.zeros(3 * N)
        rbm.mobilityTT(v, r, F)
        for i in range(N):
            for l in range(3):
                M[3 * i + l, 3 * j + k] = v[l * N + i]
for row in M:
    print(" ".join(repr(float(x)) for x in row))
