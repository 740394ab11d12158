"""PyStokes's RPY mobility product (unbounded.Rbm.mobilityTT: v = mu^TT . F, Cython, serial) at
N = 4,096 spheres, timed as `swimlab bench pairs` times swimlab's kernel: the median of 11 products,
N(N-1) pair interactions each. Run both side by side (benches/pystokes/README.md).
"""
import sys
import time

import numpy as np
import pystokes

N = int(sys.argv[1]) if len(sys.argv) > 1 else 4096
rng = np.random.default_rng(1)
# A random cloud with spheres a few radii apart, as in swimlab's bench (radius 1, box ~ N^(1/3) * 6).
side = 6.0 * N ** (1.0 / 3.0)
r = np.concatenate([rng.uniform(0, side, N) for _ in range(3)])  # x..., y..., z... (PyStokes layout)
F = rng.normal(size=3 * N)
rbm = pystokes.unbounded.Rbm(radius=1.0, particles=N, viscosity=1.0 / 6.0 / np.pi)
times = []
for _ in range(11):
    v = np.zeros(3 * N)
    t0 = time.perf_counter()
    rbm.mobilityTT(v, r, F)
    times.append(time.perf_counter() - t0)
t = float(np.median(times))
print(f"PyStokes {pystokes.__version__ if hasattr(pystokes, '__version__') else ''} mobilityTT, N = {N}: "
      f"{t:.3e} s per product, {N * (N - 1) / t:.3e} interactions/s (serial)")
