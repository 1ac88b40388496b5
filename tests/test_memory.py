"""Device memory is returned: models built and dropped one after another, and a model
that grows by repeated additions, keep the process's resident memory bounded
(Taichi 1.7 never freed vector ndarrays; :func:`tdem.state.ndarray` does). Each
measurement runs in a child process of its own, so that other tests' memory does not
count."""
import subprocess
import sys
import textwrap

import pytest

PRELUDE = textwrap.dedent("""
    import gc, os
    import numpy as np
    import tdem

    def rss():
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20

    LAW = tdem.LinearContact(kn=1e6)

    def pack(side, y0=0.0):
        xs = (np.arange(side) + 0.5) * 0.01
        return np.array([(x, y0 + y) for y in xs for x in xs])

    def build():
        sim = tdem.Simulation(gravity=(0, -9.81))
        sim.add_particles(pack(83), 0.005, density=2500.0, contact=LAW)
        sim.add_wall((0, 0), (1, 0), contact=LAW)
        sim.run(steps=2)
        return sim
""")


def _child(body):
    out = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(body)],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    return float(out.stdout.strip().splitlines()[-1])


def test_models_built_and_dropped_return_their_memory():
    # 6,889 discs each: before the fix each one kept about 20 MB
    per_model = _child("""
        build(); gc.collect()          # compiles the kernels, warms the allocator
        build(); gc.collect()
        r0 = rss()
        for _ in range(20):
            s = build()
            del s
            gc.collect()
        print((rss() - r0) / 20)
    """)
    assert per_model < 2.0, f"{per_model:.2f} MB kept per model"


def test_a_model_grown_by_additions_keeps_memory_bounded():
    # 40 additions of 400 discs each: the arrays are reallocated at every addition;
    # what stays is the final model (16,400 discs, a few tens of MB), not 40 copies
    grown = _child("""
        sim = tdem.Simulation(gravity=(0, -9.81))
        sim.add_particles(pack(20), 0.005, density=2500.0, contact=LAW)
        sim.run(steps=1)
        gc.collect()
        r0 = rss()
        for k in range(40):
            sim.add_particles(pack(20, 0.25 * (k + 1)), 0.005, density=2500.0, contact=LAW)
            sim.run(steps=1)
        gc.collect()
        print(rss() - r0)
    """)
    assert grown < 120.0, f"{grown:.0f} MB after 40 additions"
