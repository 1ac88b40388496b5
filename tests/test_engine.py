"""Engine mechanics: kernels compiled once per process, slot growth, Verlet skin."""
import numpy as np
import pytest

import tdem
import tdem.neighbors as nb
import tdem.step as stepk


def _n_compiled(kernel):
    return len(kernel._primal.compiled_kernel_data_by_key) if hasattr(
        kernel._primal, "compiled_kernel_data_by_key") else len(kernel._primal.compiled_kernels)


def _box(n_side, r, seed=0, law=None):
    rng = np.random.default_rng(seed)
    law = law or tdem.LinearContact(kn=1e5, friction=0.3, restitution=0.8)
    sim = tdem.Simulation(gravity=(0.0, -9.81))
    xs = (np.arange(n_side) + 0.5) * 2.2 * r
    pos = np.array([(x, y) for y in xs for x in xs]) + rng.uniform(-0.05, 0.05, (n_side ** 2, 2)) * r
    sim.add_particles(pos, r, density=1000.0, contact=law,
                      velocity=rng.normal(0.0, 0.1, (n_side ** 2, 2)))
    w = n_side * 2.2 * r
    for a, b in (((0, 0), (w, 0)), ((w, 0), (w, 2 * w)), ((0, 2 * w), (0, 0))):
        sim.add_wall(a, b, contact=law)
    return sim


def test_second_simulation_reuses_compiled_kernels():
    s1 = _box(6, 0.01)
    s1.run(steps=50)
    before = (_n_compiled(stepk.step), _n_compiled(nb.rebuild))
    s2 = _box(11, 0.02, seed=1)   # other size, other radius
    s2.run(steps=50)
    after = (_n_compiled(stepk.step), _n_compiled(nb.rebuild))
    assert after == before


def test_slots_grow_and_steps_are_redone():
    """A polydisperse pack whose large discs have more neighbours than the initial slots:
    the run grows the slots, and the result equals a run that started with enough."""
    pos, rad = [], []
    for i in range(28):
        for j in range(28):
            pos.append((i * 0.012, j * 0.012))
            rad.append(0.004)
    pos = np.array(pos)
    big = np.array([[0.165, 0.165]])
    keep = np.linalg.norm(pos - big, axis=1) > 0.06 + 0.004 + 0.002
    pos, rad = pos[keep], np.array(rad)[keep]
    law = tdem.LinearContact(kn=1e5, friction=0.3)

    def make(cap):
        sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-4, check_interval=20)
        sim._cap = cap
        sim.add_particles(pos, rad, density=1000.0, contact=law,
                          velocity=1.0 * (big - pos) / np.linalg.norm(big - pos, axis=1)[:, None])
        sim.add_particles(big, 0.06, density=1000.0, contact=law)
        return sim

    small = make(8)
    small.run(steps=400)
    assert small._cap > 8
    ref = make(64)
    ref.run(steps=400)
    a, b = small.particles.numpy(), ref.particles.numpy()
    np.testing.assert_allclose(a["position"], b["position"], rtol=0, atol=1e-12)


def test_lists_rebuilt_only_after_half_skin():
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt=1e-3, skin=0.01)
    law = tdem.LinearContact(kn=1e3)
    sim.add_particles([[0.0, 0.0], [1.0, 0.0]], 0.1, density=1.0, contact=law,
                      velocity=[[1.0, 0.0], [0.0, 0.0]])
    sim.run(steps=1)
    b0 = sim.neighbour_builds
    sim.run(steps=100)   # the first disc moves 0.1 m: one rebuild per 0.005 m
    assert sim.neighbour_builds - b0 == pytest.approx(100 * 1e-3 / 0.005, abs=1)


def test_moving_wall_found_after_travelling_beyond_the_skin():
    """A wall starting far away (gap >> skin) and moving at v hits a resting disc: the
    candidate list must pick it up; an elastic hit by an infinite mass gives the disc
    2 v."""
    v = -0.5
    sim = tdem.Simulation(gravity=(0.0, 0.0), dt_fraction=0.02, skin=0.002)
    law = tdem.LinearContact(kn=1e5, friction=0.0)
    sim.add_particles([[0.0, 0.0]], 0.01, density=1000.0, contact=law)
    sim.add_wall((0.1, -1.0), (0.1, 1.0), contact=law, velocity=(v, 0.0))
    sim.run(until=0.3)
    vel = sim.particles.numpy()["velocity"][0]
    assert vel[0] == pytest.approx(2 * v, rel=0.005)
    assert sim.neighbour_builds > 10


_PILE = """
import numpy as np, sys
sys.path.insert(0, {root!r})
import tdem
rng = np.random.default_rng(4)
law = tdem.LinearContact(kn=1e5, friction=0.4, restitution=0.6,
                         rolling=tdem.RollingResistance(delta=0.3, model=1))
sim = tdem.Simulation()
xy = np.stack(np.meshgrid(np.arange(15), np.arange(15)), -1).reshape(-1, 2) * 0.022 + 0.02
sim.add_particles(xy, rng.uniform(0.008, 0.0105, len(xy)), density=2000.0, contact=law)
sim.add_wall((0.0, 0.0), (0.4, 0.0), contact=law)
sim.add_wall((0.0, 1.0), (0.0, 0.0), contact=law)
sim.add_wall((0.4, 0.0), (0.4, 1.0), contact=law)
sim.run(steps=1500)
np.save(sys.argv[1], sim.particles.numpy()["position"])
print("chunk", tdem.backend.chunk_size(sim.n_particles, sim._serial()))
"""


def test_one_thread_and_parallel_paths_agree(tmp_path, summation_paths):
    """On one thread partner forces are summed directly; on two threads, directly
    within each thread's chunk of particles and through the slots across chunks; on
    the GPU's path (TDEM_CHUNKS=0, run here on the CPU) through the slots for every
    pair. The three summation orders agree to round-off, and each repeats itself bit
    for bit (TDEM_SERIAL_BELOW=0: the 225 discs would otherwise run their loops on one
    thread on all)."""
    import os
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    script = tmp_path / "pile.py"
    script.write_text(_PILE.format(root=root))
    out, chunk = summation_paths(script, tmp_path)
    # 225 discs on two threads: 8 chunks of 29 (asked: a model this small has one)
    assert chunk == {"one": 0, "chunks": 29, "chunks again": 29, "slots": 0}
    # a settling pile is chaotic: compare early enough that round-off has not grown
    np.testing.assert_allclose(out["chunks"], out["one"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(out["slots"], out["one"], rtol=0, atol=1e-9)
    assert np.array_equal(out["chunks"], out["chunks again"])


def test_device_side_rebuild_path_gives_the_same_run():
    """The GPU path launches the rebuild kernel every step and lets the device flag
    decide; run on the CPU it must give exactly the run of the host-checked path."""
    runs = []
    for host_reads_flag in (True, False):
        sim = _box(8, 0.01, seed=5)
        sim._host_reads_flag = host_reads_flag
        sim.run(steps=600)
        runs.append((sim.particles.numpy()["position"], sim.neighbour_builds))
    assert runs[0][1] == runs[1][1] > 1
    assert np.array_equal(runs[0][0], runs[1][0])


def test_law_update_takes_effect_at_the_next_run():
    """A disc sliding on a floor: frictionless it keeps its speed; after
    ``law.update(friction=0.3)`` it decelerates at μ g."""
    law = tdem.LinearContact(kn=1e6, friction=0.0)
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.1)
    m = 1000.0 * np.pi * 0.01
    sim.add_particles([[0.0, 0.1 - m * 9.81 / 1e6]], 0.1, density=1000.0, contact=law,
                      velocity=[[2.0, 0.0]])
    sim.add_wall((-10.0, 0.0), (10.0, 0.0), contact=law)
    sim.run(until=0.1)
    assert sim.particles.numpy()["velocity"][0, 0] == pytest.approx(2.0, rel=1e-6)
    with pytest.raises(tdem.InputError, match="friction"):
        law.update(friction=-1.0)
    assert law.friction == 0.0
    law.update(friction=0.3)
    v0, t0 = sim.particles.numpy()["velocity"][0, 0], sim.time
    sim.run(until=0.3)
    v1 = sim.particles.numpy()["velocity"][0, 0]
    assert (v0 - v1) / (sim.time - t0) == pytest.approx(0.3 * 9.81, rel=0.01)


def test_prescribed_velocity_as_a_function_of_time():
    """vx = 2t prescribed: x = t² (the leapfrog with v evaluated at the step's start)."""
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt=1e-3)
    g = sim.add_particles([[0.0, 0.0]], 0.1, density=1000.0, contact=tdem.LinearContact(kn=1e6))
    sim.fix_particles(g.ids, vx=lambda t: 2.0 * t, vy=0.0)
    sim.run(until=0.5)
    p = sim.particles.numpy()
    n = sim.steps
    assert p["position"][0, 0] == pytest.approx(sum(2.0 * k * 1e-3 for k in range(n)) * 1e-3,
                                                rel=1e-12)
    assert p["position"][0, 1] == 0.0
    assert p["velocity"][0, 0] == pytest.approx(2.0 * (n - 1) * 1e-3, rel=1e-12)


def test_size_rule_for_one_thread_loops(monkeypatch):
    """Loops run on one thread with one CPU thread, never on a GPU, and on several
    threads for models below the measured crossovers; TDEM_SERIAL_BELOW overrides
    the size and a bad value is named."""
    from tdem import backend
    from tdem.errors import InputError
    monkeypatch.setitem(backend._state, "arch", "cpu")
    monkeypatch.setitem(backend._state, "threads", None)
    monkeypatch.setitem(backend._state, "nthreads", 2)
    monkeypatch.delenv("TDEM_SERIAL_BELOW", raising=False)
    dem, el = backend.SERIAL_BELOW_DEM, backend.SERIAL_BELOW_ELEMENTS
    assert backend.serial_loops(dem - 1) and not backend.serial_loops(dem)
    assert backend.serial_loops(el - 1, elements=True)
    assert not backend.serial_loops(el, elements=True)
    assert not backend.serial_loops()
    # 16 threads gain more from a loop: one thread only below 0.5/(1 - 1/16) of it
    monkeypatch.setitem(backend._state, "nthreads", 16)
    assert backend.serial_below() == 6400 and backend.serial_below(True) == 1067
    assert backend.serial_loops(6399) and not backend.serial_loops(6400)
    monkeypatch.setitem(backend._state, "nthreads", 2)
    monkeypatch.setenv("TDEM_SERIAL_BELOW", "0")
    assert not backend.serial_loops(10)
    monkeypatch.setenv("TDEM_SERIAL_BELOW", "500")
    assert backend.serial_loops(499, elements=True) and not backend.serial_loops(500)
    monkeypatch.setenv("TDEM_SERIAL_BELOW", "many")
    with pytest.raises(InputError, match="TDEM_SERIAL_BELOW.*'many'"):
        backend.serial_loops(10)
    monkeypatch.setenv("TDEM_SERIAL_BELOW", "0")
    monkeypatch.setitem(backend._state, "nthreads", 1)      # a one-core machine
    assert backend.serial_loops(10 ** 6)
    monkeypatch.setitem(backend._state, "nthreads", 2)
    monkeypatch.setitem(backend._state, "threads", 1)       # TDEM_THREADS=1
    assert backend.serial_loops(10 ** 6)
    monkeypatch.setitem(backend._state, "arch", "gpu")
    assert not backend.serial_loops(1)


def test_switch_to_one_thread_loops_mid_run(monkeypatch):
    """A run whose loops go from parallel to one thread between segments (here by
    TDEM_SERIAL_BELOW) continues the parallel run to round-off: the one-thread path
    does not pick up the parallel path's last force sums."""
    runs = []
    for switch in (False, True):
        monkeypatch.setenv("TDEM_SERIAL_BELOW", "0")
        sim = _box(8, 0.01, seed=3)
        sim.run(steps=300)
        if switch:
            monkeypatch.setenv("TDEM_SERIAL_BELOW", "100000")
        sim.run(steps=300)
        assert sim._serial() == switch or tdem.backend._state["threads"] == 1
        runs.append(sim.particles.numpy()["position"])
    np.testing.assert_allclose(runs[1], runs[0], rtol=0, atol=1e-9)


def test_chunk_rule_for_the_pair_loop(monkeypatch):
    """On several CPU threads the pair loop runs in 4 chunks per thread (n/(4T)
    particles each, rounded up), none smaller than 1024 particles; none on one thread
    or a GPU; TDEM_CHUNKS fixes the count (0: a slot for every pair) and a bad value
    is named."""
    from tdem import backend
    from tdem.errors import InputError
    monkeypatch.setitem(backend._state, "arch", "cpu")
    monkeypatch.setitem(backend._state, "nthreads", 2)
    monkeypatch.delenv("TDEM_CHUNKS", raising=False)
    assert backend.chunk_size(47068, serial=False) == 5884      # 8 chunks
    assert backend.chunk_size(47068, serial=True) == 0
    assert backend.max_chunks() == 8
    assert backend.chunk_size(5000, serial=False) == 1250      # 4 chunks
    assert backend.chunk_size(225, serial=False) == 225        # one
    monkeypatch.setitem(backend._state, "nthreads", 16)
    assert backend.chunk_size(1_000_000, serial=False) == 15625 and backend.max_chunks() == 64
    monkeypatch.setenv("TDEM_CHUNKS", "3")
    assert backend.chunk_size(300, serial=False) == 100 and backend.max_chunks() == 3
    monkeypatch.setenv("TDEM_CHUNKS", "0")
    assert backend.chunk_size(300, serial=False) == 0 and backend.max_chunks() == 1
    monkeypatch.setenv("TDEM_CHUNKS", "a few")
    with pytest.raises(InputError, match="TDEM_CHUNKS.*'a few'"):
        backend.chunk_size(300, serial=False)
    monkeypatch.delenv("TDEM_CHUNKS")
    monkeypatch.setitem(backend._state, "arch", "cuda")
    assert backend.chunk_size(1_000_000, serial=False) == 0
