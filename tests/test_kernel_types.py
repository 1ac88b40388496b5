"""Every kernel builds and gives the same motion without Taichi's advanced optimisation.

CUDA builds of Taichi 1.7 need the kernels to compile with ``advanced_optimization``
off: with it on, kernels of shaped particles, PCMM bodies and blocks stop with
CUDA_ERROR_MISALIGNED_ADDRESS, so tdem turns it off on CUDA
(:func:`tdem.backend.advanced_optimization`). Without those passes, a local variable
that a kernel gives two types (a name bound to a scalar and then to a vector, e.g. one
``_`` for two ignored return values of different types) is no longer dropped
silently: the CPU LLVM backend stops the process with
``StoreInst::AssertOK(): Ptr must be a pointer to Val type!``. The CPU suite runs
with the optimisation on, so it would not notice such a variable in a kernel.

The test runs one model with every kind of kernel — discs with the linear law with
rolling resistance and with Hertz–Mindlin, superellipses, walls (one moving), a PCMM
body with a non-reflecting boundary, a JWL charge, a deformable block, a rigid block,
point–edge couplings of block to block and disc to block — a periodic pack, and in
3D spheres with an ellipsoid, spheres with a cube (both periodic along x, on a mesh
floor) and spheres with rolling resistance, on the CPU with
``TDEM_ADVANCED_OPTIMIZATION=0`` (in a process of its own) and ``=1`` (in the test's
process, when the suite runs on the CPU, so that the kernels it has built for earlier
tests are not built again). Both must finish, and positions, velocities, spins,
angles, plastic strains and energies agree to 1e-10 relative (the two builds round some floating-point operations differently:
about 1e-16 a step, which the periodic pack's many contacts grow over the 150
steps; measured up to 6e-12 in a spin).
(A 3D step once read a history column past its width in a branch that the
optimisation removed: the build without it stopped in Taichi's scalarize pass.)
The two builds run side by side. A build's time is mostly Taichi's front end (the
Python AST of 99 kernels made into IR, which the offline cache does not keep): with
the cache filled, 14 s of a process's 23 s; with it empty, 53 s.

Run as a script, this module prints the model's state as JSON on the line starting
with ``RESULT``.
"""
import json
import os
import subprocess
import sys

import numpy as np

STEPS = 150
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KEYS = ("position", "velocity", "omega", "angle")


def _laws():
    import tdem
    rolling = tdem.LinearContact(kn=1e6, friction=0.5, restitution=0.5,
                                 rolling=tdem.RollingResistance(delta=0.3, model=2))
    hertz = tdem.HertzMindlin(young=1e8, poisson=0.3, friction=0.4)
    plain = tdem.LinearContact(kn=1e6, friction=0.4, restitution=0.6)  # shapes: no rolling
    return rolling, hertz, plain


def _everything():
    """The model of tests/test_state.py with superellipses, a Mohr–Coulomb PCMM body
    under a non-reflecting boundary, everything in contact from the first step (the
    charge's small particles set a step of 0.15 µs: nothing would meet in 150 steps)."""
    import tdem
    from test_state import add_charge_and_blocks
    lin, hertz, plain = _laws()
    R = 0.01
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.3)
    # a Mohr–Coulomb PCMM body (a hexagonal pack, whose elements form) sheared by its
    # initial velocity (25 /s: it yields within the run), with discs of the two laws
    # pressed 0.1 mm into its top row
    x = tdem.pack.cross(0.2, 0.06, R, origin=(0.0, 0.0005))[0]
    body = sim.add_particles(x, R, tolerance=0.5 * R,
                             material=tdem.MohrCoulomb(density=2500.0, young=5e6, poisson=0.25,
                                                       cohesion=500.0, friction_angle=30.0),
                             velocity=np.column_stack([25.0 * (x[:, 1] - x[0, 1]),
                                                       np.zeros(len(x))]))
    sim.non_reflecting(body.ids[x[:, 1] == x[0, 1]], normal=(0.0, -1.0))
    top = x[x[:, 1] == x[:, 1].max()]
    press = top[1:8] + [0.0, 2 * R - 1e-4]
    sim.add_particles(press[:4], R, density=2500.0, contact=lin, velocity=(0.0, -0.5))
    hz = sim.add_particles(press[4:], R, density=2500.0, contact=hertz, velocity=(0.1, -0.5))
    sim.fix_particles(hz.ids[:1], vx=0.0, omega=1.0)
    # superellipses 0.1 mm into the floor and into one another: side by side, one on
    # its end, a rounder one of the other law on top
    box, round_ = tdem.Superellipse(0.015, 0.008, 4), tdem.Superellipse(0.012, 0.012, 2.5)
    y0 = box.b - 1e-4
    boxes = sim.add_particles([[0.33, y0], [0.33 + 2 * box.a - 1e-4, y0], [0.40, box.a - 1e-4]],
                              shape=box, angle=[0.0, 0.0, 90.0], density=2500.0, contact=plain,
                              velocity=[[0.2, 0.0], [0.0, -0.3], [-0.5, 0.0]])
    rounds = sim.add_particles([[0.335, 2 * box.b + round_.b - 3e-4]], shape=round_,
                               angle=10.0, density=2500.0, contact=hertz, velocity=(0.3, -0.6))
    sim.add_wall((0.0, 0.0), (0.45, 0.0), contact=lin)
    add_charge_and_blocks(sim, lin, R)
    return sim, np.concatenate([boxes.ids, rounds.ids])


def _periodic():
    """Discs that meet across the boundary of a pack periodic along x, on a floor."""
    import tdem
    lin, hertz, plain = _laws()
    sim = tdem.Simulation(gravity=(0.0, -9.81), dt_fraction=0.3)
    sim.periodic(x=(0.0, 0.2))
    sim.add_particles([[0.01, 0.012], [0.19, 0.03], [0.1, 0.02]], 0.01, density=2500.0,
                      contact=lin, velocity=[[-0.4, 0.0], [0.3, -0.2], [0.0, -0.3]])
    sim.add_particles([[0.195, 0.011], [0.05, 0.04]], 0.01, density=2500.0, contact=hertz,
                      velocity=[[0.5, 0.0], [0.0, -0.4]])
    sim.add_wall((-0.1, 0.0), (0.3, 0.0), contact=lin)
    return sim, np.zeros(0, int)


def _rolling_3d():
    """3D spheres with rolling resistance rolling on a mesh floor and into one another."""
    import tdem
    rolling = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.5, restitution=0.5,
                                rolling=tdem.RollingResistance(delta=0.3, model=1))
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=2e-5)
    r = 0.01
    sim.add_particles([[0.0, 0.0, r - 1e-4], [2 * r - 1e-4, 0.0, r - 1e-4]], r,
                      density=2500.0, contact=rolling,
                      velocity=[[0.3, 0.1, 0.0], [-0.2, 0.0, 0.0]],
                      omega=[[-10.0, 30.0, 0.0], [0.0, -20.0, 5.0]])
    v, t = tdem.surfaces.plane((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), size=0.4, divisions=2)
    sim.add_mesh(v, t, contact=rolling)
    return sim, np.zeros(0, int)


def _three_d(shape):
    """3D: spheres and an ellipsoid or a cube (the two cannot share a model) on a mesh
    floor, periodic along x, everything touching from the first step (a sphere across
    the periodic boundary)."""
    import tdem
    hertz = tdem.HertzMindlin(young=1e7, poisson=0.3, friction=0.4, restitution=0.6)
    sim = tdem.Simulation(dim=3, gravity=(0.0, 0.0, -9.81), dt=2e-5)
    sim.periodic(x=(0.0, 0.2))
    r = 0.01
    sim.add_particles([[r - 5e-5, 0.0, r - 1e-4], [0.2 - r - 5e-5, 0.0, r - 1e-4], [0.1, 0.0, r - 1e-4],
                       [0.1, 0.0, 3 * r - 3e-4]], r, density=2500.0, contact=hertz,
                      velocity=[[0.3, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, -0.2],
                                [0.1, 0.0, -0.3]])
    if shape == "ellipsoid":
        kw = dict(shape=tdem.Ellipsoid(0.015, 0.012, 0.008), contact=hertz)
    else:
        kw = dict(shape=tdem.Polyhedron.cube(0.016),
                  contact=tdem.VolumeContact(young=1e7, friction=0.5, restitution=0.5))
    half_y = 0.012 if shape == "ellipsoid" else 0.008
    body = sim.add_particles([[0.1, r + half_y - 1e-4, 0.008 - 1e-4]], density=2500.0,
                             velocity=(0.2, -0.1, 0.0), omega=(0.0, 0.0, 5.0), **kw)
    v, t = tdem.surfaces.plane((0.1, 0.0, 0.0), (0.0, 0.0, 1.0), size=0.6, divisions=4)
    sim.add_mesh(v, t, contact=hertz)
    return sim, body.ids


def _state(steps):
    out = {}
    for name, build in (("everything", _everything), ("periodic", _periodic),
                        ("ellipsoids", lambda: _three_d("ellipsoid")),
                        ("polyhedra", lambda: _three_d("cube")), ("rolling_3d", _rolling_3d)):
        sim, shapes = build()
        turn = "angle" if sim.dim == 2 else "orientation"     # (3D: quaternions)
        start = sim.particles.numpy()[turn][shapes]
        sim.run(steps=steps)
        p = dict(sim.particles.numpy())
        p["angle"] = p[turn]
        out[name] = {k: np.asarray(p[k]).tolist() for k in KEYS}
        out[name]["shape_turn"] = (p["angle"][shapes] - start).tolist()
        out[name]["plastic_strain"] = np.asarray(p.get("plastic_strain", [])).tolist()
        out[name]["energy"] = sim.energy()
        out[name]["steps"] = sim.steps
        out[name]["contacts"] = len(sim.contacts.numpy()["pairs"])
    return out


def _run(optimise):
    env = dict(os.environ, TDEM_ADVANCED_OPTIMIZATION=str(optimise), TDEM_ARCH="cpu",
               TDEM_SERIAL_BELOW="0")       # the parallel loops, as on a GPU
    env["PYTHONPATH"] = os.pathsep.join(p for p in (ROOT, env.get("PYTHONPATH")) if p)
    return subprocess.Popen([sys.executable, os.path.abspath(__file__), str(STEPS)], env=env,
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def _result(proc, optimise):
    out, err = proc.communicate(timeout=900)
    assert proc.returncode == 0, (f"TDEM_ADVANCED_OPTIMIZATION={optimise}: exit "
                                  f"{proc.returncode}\n{err[-4000:]}")
    lines = [ln for ln in out.splitlines() if ln.startswith("RESULT ")]
    assert lines, f"TDEM_ADVANCED_OPTIMIZATION={optimise}: no result\n{err[-4000:]}"
    return json.loads(lines[-1][len("RESULT "):])


def ti_cfg():
    from taichi.lang import impl
    return impl.current_cfg()


def _close(a, b, what):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape, what
    assert np.isfinite(a).all() and np.isfinite(b).all(), what
    scale = np.abs(b).max() if b.size else 0.0
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-10 * scale, err_msg=what)


def test_kernels_build_and_agree_with_and_without_advanced_optimisation():
    # the build without the optimisation in a process of its own; the build with it
    # here, in the suite's process (on the CPU it is the default, and the kernels
    # this process has built already are not built again), while the other runs
    from tdem import backend
    here = int(bool(ti_cfg().advanced_optimization)) if backend.init() == "cpu" else None
    procs = {o: _run(o) for o in (0, 1) if o != here}
    try:
        got = {} if here is None else {here: json.loads(json.dumps(_state(STEPS)))}
        got.update({o: _result(procs[o], o) for o in procs})
        off, on = got[0], got[1]
    finally:
        for proc in procs.values():
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
    for model in ("everything", "periodic", "ellipsoids", "polyhedra", "rolling_3d"):
        a, b = off[model], on[model]
        assert a["steps"] == b["steps"] == STEPS
        for k in KEYS + ("plastic_strain",):
            _close(a[k], b[k], f"{model}: {k}")
        ea, eb = a["energy"], b["energy"]
        assert ea.keys() == eb.keys()
        _close([ea[k] for k in sorted(ea)], [eb[k] for k in sorted(eb)], f"{model}: energy")
    # the run does what it should exercise: contacts, a burning charge, plastic flow
    # in the body, turning superellipses, a periodic pack
    ev = on["everything"]
    assert ev["contacts"] > 10
    assert ev["energy"]["explosive"] > 0.0
    assert max(ev["plastic_strain"]) > 0.0
    assert (np.abs(ev["shape_turn"]) > 1e-6).all(), ev["shape_turn"]
    pos = np.asarray(on["periodic"]["position"])
    assert ((pos[:, 0] >= 0.0) & (pos[:, 0] < 0.2)).all()
    # 3D: the shapes and the spheres in contact and turning, the periodic axis
    for model in ("ellipsoids", "polyhedra"):
        td = on[model]
        assert td["contacts"] >= 3, model
        assert (np.abs(td["shape_turn"]) > 1e-6).any(), (model, td["shape_turn"])
        pos = np.asarray(td["position"])
        assert ((pos[:, 0] >= 0.0) & (pos[:, 0] < 0.2)).all(), model

if __name__ == "__main__":
    print("RESULT " + json.dumps(_state(int(sys.argv[1]) if len(sys.argv) > 1 else STEPS)))
