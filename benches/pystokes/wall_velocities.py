"""PyStokes's wall-bounded velocities for the spheres and forces of wall_velocities.rhai, against
swimlab's. python wall_velocities.py wv.txt (the .rhai script's output)."""
import ast
import sys

import numpy as np
import pystokes

lines = open(sys.argv[1]).read().strip().splitlines()
ours = np.array(ast.literal_eval(lines[0]))
X = []
for line in lines[1:]:
    c, d, L = ast.literal_eval(line)
    c, d = np.array(c), np.array(d) / np.linalg.norm(d)
    X += [c - L / 2 * d, c + L / 2 * d]  # the a1 sphere, then the a2 sphere
X = np.array(X)
N = len(X)
F = np.array([[1e-12, 0, 0], [0, 2e-12, 0], [0, 0, 3e-12], [-1e-12, 1e-12, -2e-12]])
v = np.zeros(3 * N)
pystokes.wallBounded.Rbm(radius=1e-6, particles=N, viscosity=1e-3).mobilityTT(
    v, np.concatenate([X[:, 0], X[:, 1], X[:, 2]]), np.concatenate([F[:, 0], F[:, 1], F[:, 2]]))
theirs = np.stack([v[:N], v[N:2 * N], v[2 * N:]], axis=1)
print("largest relative difference:", np.abs(ours - theirs).max() / np.abs(theirs).max())
print("per sphere:", np.abs(ours - theirs).max(axis=1) / np.abs(theirs).max())
