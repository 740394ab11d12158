"""SciPy's solve_ivp on the Fig-1 mirror pair, written from the model's equations alone (sphere
positions, springs, RPY): the side-by-side reference of README's speed figures (see README.md here).

Usage: python fig1_pair.py REFERENCE_DRIFT [PERIODS]
Prints, per method and rtol, the wall time of PERIODS periods from t = 0 and the relative error of
the pair's mean x-displacement against REFERENCE_DRIFT (swimlab's dopri5(1e-11) value, m).
"""
import sys, time
import numpy as np
from scipy.integrate import solve_ivp

mu, ell, lam, omega, k0 = 1e-3, 5e-6, 0.5e-6, 500.0, 1e-3
a1, a2 = 1.125e-6, 0.5625e-6
radii = np.array([a1, a2, a1, a2])
phases = [0.0, np.pi / 2]

def rest(t, phi):
    return ell + lam * np.sin(omega * t + phi)

def initial():
    x = []
    for centre, n, phi in [(-25e-6, 1.0, phases[0]), (25e-6, -1.0, phases[1])]:
        L = rest(0.0, phi)
        b = np.array([n * L, 0.0, 0.0])
        rh = np.array([centre, 0.0, 0.0])
        x += [rh - a2 / (a1 + a2) * b, rh + a1 / (a1 + a2) * b]
    return np.concatenate(x)

OFF = ~np.eye(4, dtype=bool)
S2 = radii[:, None] ** 2 + radii[None, :] ** 2

def rhs(t, y):
    """Sphere velocities: Stokes drag of each sphere's own force plus RPY interactions, vectorised."""
    X = y.reshape(4, 3)
    b = X[1::2] - X[0::2]
    d = np.linalg.norm(b, axis=1)
    L = ell + lam * np.sin(omega * t + np.array(phases))
    f = (k0 * (d - L) / d)[:, None] * b
    F = np.empty((4, 3))
    F[0::2], F[1::2] = f, -f
    V = F / (6 * np.pi * mu * radii[:, None])
    r = X[:, None, :] - X[None, :, :]
    dist = np.linalg.norm(r, axis=2)
    np.fill_diagonal(dist, 1.0)
    e = r / dist[..., None]
    eF = np.einsum("ijk,jk->ij", e, F)
    c1 = (1 + S2 / (3 * dist**2)) / (8 * np.pi * mu * dist)
    c2 = (1 - S2 / dist**2) / (8 * np.pi * mu * dist)
    c1[~OFF] = 0.0
    c2[~OFF] = 0.0
    V += np.einsum("ij,jk->ik", c1, F) + np.einsum("ij,ij,ijk->ik", c2, eF, e)
    return V.ravel()

def mean_drift(y, y0):
    rh = lambda Y, s: (a1 * Y[6 * s:6 * s + 3] + a2 * Y[6 * s + 3:6 * s + 6]) / (a1 + a2)
    return 0.5 * ((rh(y, 0) - rh(y0, 0))[0] + (rh(y, 1) - rh(y0, 1))[0])

if __name__ == "__main__":
    ref = float(sys.argv[1])
    periods = float(sys.argv[2]) if len(sys.argv) > 2 else 100.0
    T = 2 * np.pi / omega
    y0 = initial()
    for method in ["RK45", "DOP853", "LSODA", "BDF", "Radau"]:
        for rtol in [1e-6, 3e-7, 1e-7, 3e-8, 1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 1e-11]:
            start = time.perf_counter()
            sol = solve_ivp(rhs, (0.0, periods * T), y0, method=method, rtol=rtol, atol=rtol * 1e-6)
            wall = time.perf_counter() - start
            err = abs(mean_drift(sol.y[:, -1], y0) - ref) / abs(ref)
            print(f"{method:7s} rtol {rtol:.0e}: {wall:8.3f} s, relative drift error {err:.2e}, nfev {sol.nfev}", flush=True)
            if err <= 1e-3:
                break
