"""The 3D sphere pack's step written bare: what Taichi's CPU code reaches for it.

One Taichi kernel with nothing but the physics of the workload (``pack3d.py``): the
Hertz–Mindlin pair force with its shear spring turned onto the tangent plane and the
Coulomb limit (the formulas of ``physics.hertz_mindlin``, its constants folded in at
compile time; the turned spring's length always restored by the series the engine uses
for small turns), each pair once with the partner's share added on the spot (a serial
loop: one thread, whatever ``--threads`` says),
the five walls as planes (without shear springs), and a plain leapfrog. Left out,
against the engine's step: the energy and work account, the orientations, the law and
shape dispatch (per-pair radii, masses and law parameters), mesh walls, damping and
fixes, and every check.

It goes on from the engine's bed after its timed steps (positions, velocities, spins
and the pairs' shear springs), with half neighbour lists of the same skin built on the
host by ``scipy.spatial.cKDTree`` whenever a sphere has moved half the skin (the
springs carried over); the timing leaves those builds out (they are 4 % of the
engine's time on this workload). It runs twice: its state in Taichi ndarrays (as the
engine keeps it) and in Taichi fields. Its rate beside the engine's and LIGGGHTS'
says how much of a gap is the engine's generality and how much is the code Taichi
emits for this loop.

    python benchmarks/pack3d.py --threads 1 --bare
"""
import math
import time

import numpy as np

CHUNK = 20          # steps between the host's displacement checks


def _lists(pts, reach, cap):
    """Half neighbour lists (each pair once, by its lower index) within ``reach``."""
    from scipy.spatial import cKDTree
    pairs = cKDTree(pts).query_pairs(reach, output_type="ndarray")
    pairs.sort(axis=1)
    pairs = pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    n = len(pts)
    counts = np.bincount(pairs[:, 0], minlength=n)
    if counts.max() > cap:
        raise RuntimeError(f"a sphere has {counts.max()} partners, more than {cap}")
    slot = np.arange(len(pairs)) - np.repeat(np.cumsum(counts) - counts, counts)
    nbr = -np.ones((n, cap), np.int32)
    nbr[pairs[:, 0], slot] = pairs[:, 1]
    return pairs, slot, nbr, counts.astype(np.int32)


def _springs(pairs, slot, n, cap, old_pairs, old_springs):
    """The springs of ``old_pairs`` (rows i < j) moved to the slots of ``pairs``."""
    out = np.zeros((n, cap, 3))
    key = {(int(a), int(b)): r for r, (a, b) in enumerate(old_pairs)}
    for r, (a, b) in enumerate(pairs):
        c = key.get((int(a), int(b)))
        if c is not None:
            out[a, slot[r]] = old_springs[c]
    return out


def measure(state, steps, contacts=None, radius=0.002, density=2500.0, young=1e7,
            poisson=0.3, restitution=0.5, friction=0.5, dt=1e-5, skin=0.0004,
            box=(0.12, 0.12), storage="ndarray", cap=16):
    """Particle-steps per second of the bare step on ``state`` (the engine's
    ``sim.particles.numpy()``), the pairs' springs taken from ``contacts`` (the
    engine's ``sim.contacts.numpy()``)."""
    import taichi as ti

    pts = np.ascontiguousarray(state["position"], dtype=float)
    n = len(pts)
    m = density * 4.0 / 3.0 * math.pi * radius ** 3
    inertia = 0.4 * m * radius ** 2
    e_star = young / (2.0 * (1.0 - poisson ** 2))
    g_star = young / (2.0 * (1.0 + poisson)) / (2.0 * (2.0 - poisson))
    le = math.log(1.0 / restitution)
    gamma = 2.0 * math.sqrt(5.0 / 6.0) * le / math.sqrt(math.pi ** 2 + le ** 2)
    reach = 2.0 * radius + skin

    pairs, slot, nbr, counts = _lists(pts, reach, cap)
    springs = np.zeros((n, cap, 3))
    if contacts is not None:
        cp = np.asarray(contacts["pairs"])
        keep = cp.min(axis=1) >= 0          # sphere pairs (walls are negative)
        springs = _springs(pairs, slot, n, cap, np.sort(cp[keep], axis=1),
                           np.asarray(contacts["spring"])[keep])
    touching_start = int(np.count_nonzero(np.abs(springs).sum(-1)))

    if storage == "field":
        def vec(w, shape):
            return ti.Vector.field(w, float, shape)
        nb, nc = ti.field(ti.i32, (n, cap)), ti.field(ti.i32, n)
        kind = ti.template()
    else:
        def vec(w, shape):
            return ti.Vector.ndarray(w, float, shape)
        nb, nc = ti.ndarray(ti.i32, (n, cap)), ti.ndarray(ti.i32, n)
        kind = ti.types.ndarray()
    pos, vel, om, acc, hist = vec(3, n), vec(3, n), vec(3, n), vec(6, n), vec(3, (n, cap))
    pos.from_numpy(pts)
    vel.from_numpy(np.ascontiguousarray(state["velocity"], dtype=float))
    om.from_numpy(np.ascontiguousarray(state["omega"], dtype=float))
    nb.from_numpy(nbr)
    nc.from_numpy(counts)
    hist.from_numpy(springs)
    d2, reff, meff = 2.0 * radius, 0.5 * radius, 0.5 * m
    wx, wy = box

    @ti.func
    def force(u, nrm, vrel, reff, meff, h):
        vn = vrel.dot(nrm)
        vt = vrel - vn * nrm
        a = ti.sqrt(reff * u)
        kn = 2.0 * e_star * a
        fel = 4.0 / 3.0 * e_star * a * u
        fn = fel - gamma * ti.sqrt(kn * meff) * vn
        m2 = h.dot(h)
        if m2 > 0.0:
            hn = h.dot(nrm)
            x = hn * hn / m2
            h = (h - hn * nrm) * (1.0 + x * (0.5 + 0.375 * x))
        fs = h + 8.0 * g_star * a * vt * dt
        fmax = friction * fel
        ft = fs
        mag2 = fs.dot(fs)
        if mag2 > fmax * fmax:
            fs *= fmax / ti.sqrt(mag2)
            ft = fs
        return -fn * nrm + ft, fs

    @ti.kernel
    def step(pos: kind, vel: kind, om: kind, acc: kind, hist: kind, nb: kind, nc: kind):
        ti.loop_config(serialize=True)
        for i in range(n):
            xi, vi, wi = pos[i], vel[i], om[i]
            f = ti.Vector([0.0, 0.0, 0.0])
            t = ti.Vector([0.0, 0.0, 0.0])
            for k in range(nc[i]):
                j = nb[i, k]
                d = pos[j] - xi
                r2 = d.dot(d)
                if r2 < d2 * d2:
                    dist = ti.sqrt(r2)
                    nrm = d / dist
                    arm = 0.5 * dist
                    vrel = vel[j] - vi - arm * (om[j] + wi).cross(nrm)
                    fk, fs = force(d2 - dist, nrm, vrel, reff, meff, hist[i, k])
                    hist[i, k] = fs
                    mk = arm * nrm.cross(fk)
                    f += fk
                    t += mk
                    acc[j] += ti.Vector([-fk[0], -fk[1], -fk[2], mk[0], mk[1], mk[2]])
                elif hist[i, k][0] != 0.0:
                    hist[i, k] = ti.Vector([0.0, 0.0, 0.0])
            # the five walls as planes (their shear springs left out)
            for ax in ti.static(range(3)):
                for side in ti.static(range(2 if ax < 2 else 1)):
                    wall = (wx, wy, 0.0)[ax] * side
                    gap = xi[ax] - wall if side == 0 else wall - xi[ax]
                    if gap < radius:
                        nrm = ti.Vector([0.0, 0.0, 0.0])
                        nrm[ax] = -1.0 if side == 0 else 1.0
                        fk, fs = force(radius - gap, nrm, -vi - radius * wi.cross(nrm),
                                       radius, m, ti.Vector([0.0, 0.0, 0.0]))
                        f += fk
                        t += radius * nrm.cross(fk)
            acc[i] += ti.Vector([f[0], f[1], f[2], t[0], t[1], t[2]])
        ti.loop_config(serialize=True)
        for i in range(n):
            a = acc[i]
            acc[i] = a * 0.0
            v1 = vel[i] + (ti.Vector([a[0], a[1], a[2]]) / m
                           + ti.Vector([0.0, 0.0, -9.81])) * dt
            vel[i] = v1
            om[i] += ti.Vector([a[3], a[4], a[5]]) / inertia * dt
            pos[i] += v1 * dt

    args = (pos, vel, om, acc, hist, nb, nc)
    step(*args)             # compiled here (one step more than timed)
    ti.sync()
    seconds, done, builds = 0.0, 0, 0
    ref = pos.to_numpy()
    while done < steps:
        k = min(CHUNK, steps - done)
        t0 = time.perf_counter()
        for _ in range(k):
            step(*args)
        ti.sync()
        seconds += time.perf_counter() - t0
        done += k
        now = pos.to_numpy()
        if np.einsum("ij,ij->i", now - ref, now - ref).max() > (0.5 * skin) ** 2:
            # a new list, the springs carried over (not timed)
            old_pairs, old = pairs, hist.to_numpy()[pairs[:, 0], slot]
            pairs, slot, nbr, counts = _lists(now, reach, cap)
            nb.from_numpy(nbr)
            nc.from_numpy(counts)
            hist.from_numpy(_springs(pairs, slot, n, cap, old_pairs, old))
            ref = now
            builds += 1
    touching = int(np.count_nonzero(np.abs(hist.to_numpy()).sum(-1)))
    return {"rate": n * steps / seconds, "seconds": seconds, "pairs": len(pairs),
            "touching_start": touching_start, "touching_end": touching, "builds": builds}
