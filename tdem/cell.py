"""A cubical stress-controlled cell (3D): six planar walls around a box of spheres,
each pair of opposite walls servo-controlled to a stress on its axis or driven at a
strain rate — the true-triaxial cell of laboratory practice and of PFC's and Yade's
triaxial examples (Yade's ``TriaxialStressController``).

Conventions
-----------
- Compression-positive stresses and strains. Axis 0, 1, 2 are x, y, z; the axial
  (loading) axis of a triaxial compression is z, the lateral axes x and y.
- The walls are squares (``tdem.surfaces.plane``) wider than the box by ``overhang``
  of its largest side beyond each edge, so that they keep covering the specimen's
  faces while it deforms; walls of different axes overlap at the edges (walls do not
  meet walls). Each wall's position on its axis is the mean of its corners.
- Lengths ``L_a`` are the distances between opposite walls, the face area of axis a
  is ``A_a = L_b L_c`` (the current one), the volume ``L_x L_y L_z``.
- Wall stresses: ``σ_a = (F_hi,a − F_lo,a)/(2 A_a)``, the mean of the two opposite
  walls' normal forces over the current face area (``Mesh.force``, the last step's).
- Measured stress: ``sim.measure(box=...)`` (:mod:`tdem.measure`, the Love–Weber
  stress of the particles whose centres lie in the box, as PFC's measurement
  spheres) over the box of the walls shrunk by ``margin`` on every side, sign turned
  to compression-positive.
- Strains from the start of a compression: axial ``ε_a = (L_z0 − L_z)/L_z0``, lateral
  ``(L_x0 − L_x)/L_x0`` and ``(L_y0 − L_y)/L_y0``, volumetric ``(V_0 − V)/V_0``
  (dilation negative).

Control
-------
A stress-controlled axis has both its walls on the engine's servo
(:meth:`tdem.handles.Mesh.servo`) with the target force ``σ × A_a``, ``A_a`` the face
area when the target was set. The servo is a proportional controller: a wall that
has to keep moving (the specimen dilates, the face area changes) lags behind its
target by a force proportional to its speed. As in the 2D biaxial specimen
(``cases/_specimen.py``), the cell runs in segments of ``update_strain`` of axial
strain; between them it resets every target force on the current areas and adds an
integral term: each axis's target is raised by ``integral_gain`` × the mean stress
error of the segment just run. A strain-controlled axis has its walls moving towards
each other at ``±0.5 ε̇ L`` (a constant true strain rate ``ε̇``).
"""
import math

import numpy as np

from .errors import InputError

AXES = ("x", "y", "z")
#: the walls' names: (axis, side) -> name
WALL_NAMES = {(0, 0): "x0", (0, 1): "x1", (1, 0): "y0", (1, 1): "y1",
              (2, 0): "z0", (2, 1): "z1"}
#: what a compression may hold constant (:meth:`TriaxialCell.compress`)
HOLDS = ("sigma3", "p")


def _positive(name, value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    if not (v > 0.0 and math.isfinite(v)):
        raise InputError(f"{name} must be a positive finite number, got {value!r}")
    return v


def _fraction(name, value, lo=0.0, hi=1.0, lo_open=True, hi_open=False):
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = float("nan")
    ok = (v > lo if lo_open else v >= lo) and (v < hi if hi_open else v <= hi)
    if not ok:
        raise InputError(f"{name} must lie in {'(' if lo_open else '['}{lo:g}, {hi:g}"
                         f"{')' if hi_open else ']'}, got {value!r}")
    return v


def _whole(name, value, least=1):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer)) \
            or int(value) != value or value < least:
        raise InputError(f"{name} must be a whole number >= {least}, got {value!r}")
    return int(value)


class TriaxialCell:
    """Six planar walls around the box [``lower``, ``upper``] of a 3D simulation, each
    pair servo-controlled to a stress on its axis or driven at a strain rate.

    Parameters
    ----------
    sim : tdem.Simulation, 3D; its particles (spheres) lie inside the box (they may
        be added before or after the cell)
    lower, upper : 3 numbers each, the box's corners (m); the walls' faces start there
    contact : a contact law (``tdem.LinearContact``, ``tdem.HertzMindlin``, …), the
        walls' law against the particles (usually frictionless)
    overhang : float >= 0, how far each wall reaches beyond the box's edges, as a
        fraction of the box's largest side (default 0.25: the specimen may shorten or
        widen by 50 % before a face is uncovered)
    margin : float >= 0 or None, the measured stress's box is the walls' box shrunk by
        this much on every side (m; default: the largest sphere's diameter, when the
        particles are known)

    Attributes
    ----------
    sim : tdem.Simulation
    walls : dict name -> tdem.Mesh, ``"x0"``, ``"x1"``, ``"y0"``, ``"y1"``, ``"z0"``,
        ``"z1"`` (lower and upper wall of each axis)
    confining : float or None, the stress of the last :meth:`consolidate` (Pa)
    """

    def __init__(self, sim, lower, upper, contact, overhang=0.25, margin=None):
        from .surfaces import plane
        if getattr(sim, "dim", None) != 3:
            raise InputError(f"sim must be a 3D tdem.Simulation (dim=3), got {sim!r}")
        try:
            lo = np.asarray(lower, dtype=float).reshape(3)
            hi = np.asarray(upper, dtype=float).reshape(3)
        except (TypeError, ValueError):
            raise InputError(f"lower and upper must be 3 numbers each, got lower={lower!r}, "
                             f"upper={upper!r}") from None
        if not (np.all(np.isfinite([lo, hi])) and np.all(hi > lo)):
            raise InputError(f"upper must exceed lower on every axis, got lower={lower!r}, "
                             f"upper={upper!r}")
        try:
            overhang = float(overhang)
        except (TypeError, ValueError):
            overhang = float("nan")
        if not (overhang >= 0.0 and math.isfinite(overhang)):
            raise InputError(f"overhang must be a number >= 0, got {overhang!r}")
        if margin is not None:
            try:
                m = float(margin)
            except (TypeError, ValueError):
                m = float("nan")
            if not (m >= 0.0 and math.isfinite(m)):
                raise InputError(f"margin must be None or a number >= 0, got {margin!r}")
            margin = m
        self.sim = sim
        self.margin = margin
        self.confining = None
        self.history = {}
        self._tag = 0
        centre = 0.5 * (lo + hi)
        size = float((hi - lo).max()) * (1.0 + 2.0 * overhang)
        self.walls = {}
        for (axis, side), name in WALL_NAMES.items():
            point = centre.copy()
            point[axis] = (lo, hi)[side][axis]
            normal = np.zeros(3)
            normal[axis] = 1.0 if side == 0 else -1.0
            v, t = plane(point, normal, size, divisions=1)
            self.walls[name] = sim.add_mesh(v, t, contact=contact)
        self._inward = {name: np.eye(3)[axis] * (1.0 if side == 0 else -1.0)
                        for (axis, side), name in WALL_NAMES.items()}

    def __repr__(self):
        lx, ly, lz = self.lengths
        return f"TriaxialCell({lx:.4g} x {ly:.4g} x {lz:.4g} m)"

    # ---------------------------------------------------------------- geometry
    def _positions(self, rows=None):
        """(3, 2) wall positions on their axes: [axis, lower/upper]."""
        rows = self.sim._wall_rows() if rows is None else rows
        from . import step as stepk
        out = np.empty((3, 2))
        for (axis, side), name in WALL_NAMES.items():
            first, count = self.sim._meshes[self.walls[name].index]
            r = rows[first:first + count]
            out[axis, side] = np.mean([r[:, stepk.T_AX + axis], r[:, stepk.T_BX + axis],
                                       r[:, stepk.T_CX + axis]])
        return out

    def bounds(self):
        """(lower (3,), upper (3,)): the walls' box now (m)."""
        p = self._positions()
        return p[:, 0].copy(), p[:, 1].copy()

    @property
    def lengths(self):
        """(3,) distances between opposite walls (m)."""
        p = self._positions()
        return p[:, 1] - p[:, 0]

    @property
    def volume(self):
        """The box's volume L_x L_y L_z (m³)."""
        return float(np.prod(self.lengths))

    def solid_volume(self):
        """Σ 4/3 π r³ of the simulation's particles (spheres) (m³)."""
        r = self.sim._radii()
        return float(np.sum(4.0 / 3.0 * math.pi * r ** 3))

    def porosity(self):
        """1 − (volume of the spheres)/(volume of the box)."""
        return 1.0 - self.solid_volume() / self.volume

    def void_ratio(self):
        """(volume of the box − volume of the spheres)/(volume of the spheres)."""
        return self.volume / self.solid_volume() - 1.0

    def _state(self):
        """(σ (3,), L (3,)) from the walls now."""
        sim = self.sim
        loads = sim._wall_loads()
        p = self._positions()
        length = p[:, 1] - p[:, 0]
        area = np.array([length[1] * length[2], length[0] * length[2],
                         length[0] * length[1]])
        sigma = np.empty(3)
        for axis in range(3):
            f = []
            for side in (0, 1):
                first, count = sim._meshes[self.walls[WALL_NAMES[(axis, side)]].index]
                f.append(float(loads[first:first + count, axis].sum()))
            sigma[axis] = 0.5 * (f[1] - f[0]) / area[axis]
        return sigma, length

    def wall_stresses(self):
        """(3,) σ_x, σ_y, σ_z (Pa, compression-positive) from the walls' forces of the
        last step over the current face areas."""
        return self._state()[0]

    def measured_stress(self, margin=None):
        """(3, 3) stress tensor (Pa, compression-positive) of ``sim.measure`` over the
        walls' box shrunk by ``margin`` (default: the cell's, else the largest
        sphere's diameter) on every side."""
        if margin is None:
            margin = self.margin
        if margin is None:
            r = self.sim._radii()
            margin = 2.0 * float(r.max()) if len(r) else 0.0
        lo, hi = self.bounds()
        if not np.all(hi - lo > 2.0 * margin):
            raise InputError(f"margin={margin!r} leaves no box inside the cell "
                             f"(sides {(hi - lo).tolist()})")
        return -np.asarray(self.sim.measure(box=(lo + margin, hi - margin))["stress"])

    # ---------------------------------------------------------------- control
    def stop(self):
        """Every wall at rest, its servo off."""
        for wall in self.walls.values():
            wall.servo()

    def _servo_axis(self, axis, sigma, length, relaxation, max_speed):
        area = float(np.prod(np.delete(length, axis)))
        for side in (0, 1):
            name = WALL_NAMES[(axis, side)]
            self.walls[name].servo(force=sigma * area, direction=self._inward[name],
                                   relaxation=relaxation, max_speed=max_speed)

    def _drive_axis(self, axis, rate, length):
        for side in (0, 1):
            name = WALL_NAMES[(axis, side)]
            self.walls[name].servo()
            self.walls[name].velocity = 0.5 * rate * float(length[axis]) * self._inward[name]

    def _mean_state(self, steps, samples=10):
        """Run ``steps`` steps; the mean wall stresses over ``samples`` readings and the
        lengths at the end."""
        per = max(1, steps // samples)
        acc = np.zeros(3)
        k = done = 0
        while done < steps:
            n = min(per, steps - done)
            self.sim.run(steps=n)
            done += n
            acc += self._state()[0]
            k += 1
        return acc / k, self._state()[1]

    def consolidate(self, p, tolerance=0.01, chunk=500, settle_chunks=3, max_steps=400000,
                    relaxation=0.5, max_speed=None, volume_tolerance=1e-4):
        """Servo all six walls to the isotropic stress ``p`` (Pa) and run until the cell
        is at rest under it: ``settle_chunks`` consecutive chunks of ``chunk`` steps in
        which the mean wall stress of every axis is within ``tolerance`` of ``p`` and
        the volume changes by less than ``volume_tolerance`` of itself. The targets are
        reset on the current face areas before each chunk. Returns the steps run;
        raises :class:`RuntimeError` after ``max_steps`` steps without rest."""
        p = _positive("p", p)
        tolerance = _positive("tolerance", tolerance)
        chunk = _whole("chunk", chunk)
        settle_chunks = _whole("settle_chunks", settle_chunks)
        max_steps = _whole("max_steps", max_steps)
        volume_tolerance = _positive("volume_tolerance", volume_tolerance)
        relaxation = _fraction("relaxation", relaxation)
        start = self.sim.steps
        calm = 0
        v_prev = self.volume
        while self.sim.steps - start < max_steps:
            length = self.lengths
            for axis in range(3):
                self._servo_axis(axis, p, length, relaxation, max_speed)
            sigma, length = self._mean_state(chunk)
            v = float(np.prod(length))
            ok = bool(np.all(np.abs(sigma / p - 1.0) < tolerance)
                      and abs(v - v_prev) < volume_tolerance * v)
            calm = calm + 1 if ok else 0
            v_prev = v
            if calm >= settle_chunks:
                self.confining = p
                return self.sim.steps - start
        raise RuntimeError(f"the cell did not come to rest under {p:g} Pa in {max_steps} "
                           f"steps (stresses {self.wall_stresses().tolist()} Pa, volume "
                           f"{self.volume:.6g} m³)")

    def compress(self, strain_rate, axial_strain, hold="sigma3", stress=None,
                 record_every=50, update_strain=5e-4, integral_gain=0.5, relaxation=0.5,
                 max_speed=None, measure_every=None):
        """Drained triaxial compression: the z walls move towards each other at the
        true strain rate ``strain_rate`` (1/s) until the axial strain is
        ``axial_strain``, while the x and y walls hold ``hold``:

        - ``"sigma3"``: σ_x = σ_y = ``stress`` (constant σ3);
        - ``"p"``: the mean stress (σ_x + σ_y + σ_z)/3 = ``stress`` (constant p): every
          update sets the lateral target to 3p/(η + 2), η = σ_z/σ_lateral the stress
          ratio of the segment just run (the σ3 at which p is met if the specimen
          keeps that ratio; (3p − σ_z)/2 instead would feed the change of σ_z that a
          change of σ3 causes back with a gain of about σ1/(2σ3), over 1 at failure,
          and oscillate); the integral term makes up the mean stress's error and
          keeps σ_x = σ_y.

        ``stress`` defaults to :attr:`confining`. Targets are reset every
        ``update_strain`` of axial strain (at least ``record_every`` steps apart) on the
        current face areas, with the integral correction of the module docstring
        (``integral_gain`` in [0, 1]); ``relaxation`` and ``max_speed`` are the lateral
        servos' (:meth:`tdem.handles.Mesh.servo`). The walls' stresses and the lengths
        are recorded every ``record_every`` steps (a monitor of the simulation,
        ``cellK``, K counting this cell's compressions); ``measure_every`` updates (None:
        never) the stress of :meth:`measured_stress` too.

        Returns
        -------
        dict of numpy arrays: time (s from the start), sigma (K, 3) wall stresses σ_x,
        σ_y, σ_z (Pa), sigma1 (σ_z), sigma2 (σ_x), sigma3 (σ_y), q = σ1 − (σ2 + σ3)/2,
        p = (σ1 + σ2 + σ3)/3, lengths (K, 3), strain (K, 3), axial_strain,
        volumetric_strain, void_ratio, target (K,) the lateral target stress without
        its integral correction; measured_time, measured_axial_strain, measured_sigma
        (M, 3, 3) (empty without ``measure_every``); and floats hold_stress,
        strain_rate, and hold (the string)."""
        strain_rate = _positive("strain_rate", strain_rate)
        axial_strain = _fraction("axial_strain", axial_strain, hi_open=True)
        if hold not in HOLDS:
            raise InputError(f"hold must be one of {HOLDS}, got {hold!r}")
        if stress is None:
            if self.confining is None:
                raise InputError("stress must be given, or the cell consolidated first "
                                 "(cell.confining is None)")
            stress = self.confining
        stress = _positive("stress", stress)
        record_every = _whole("record_every", record_every)
        update_strain = _positive("update_strain", update_strain)
        integral_gain = _fraction("integral_gain", integral_gain, lo_open=False)
        relaxation = _fraction("relaxation", relaxation)
        if measure_every is not None:
            measure_every = _whole("measure_every", measure_every)
        sim = self.sim
        update_every = max(record_every, int(round(update_strain / (strain_rate * sim.dt))))
        name = f"cell{self._tag}"
        while name in sim.histories():
            self._tag += 1
            name = f"cell{self._tag}"
        self._tag += 1
        s0, l0 = self._state()
        t0 = sim.time
        mon = sim.monitor(name, lambda s: np.concatenate(self._state()), every=record_every)
        rec_t, rec_v = [0.0], [np.concatenate([s0, l0])]
        targets = []
        meas_t, meas_e, meas_s = [], [], []
        correction = np.zeros(3)
        seen = 0
        ratio = s0[2] / max(0.5 * (s0[0] + s0[1]), 1e-12)
        target = stress
        updates = 0
        length = l0
        while length[2] > (1.0 - axial_strain) * l0[2]:
            new = mon.values[seen:]
            if new:
                v = np.asarray(new)
                if hold == "sigma3":
                    correction[:2] += integral_gain * (target - v[:, :2].mean(axis=0))
                else:
                    # the mean stress's error, made up by the lateral walls, and their
                    # own errors against their common target
                    lateral = v[:, :2].mean(axis=0)
                    correction[:2] += integral_gain * (
                        1.5 * (stress - float(v[:, :3].mean()))
                        + (lateral.mean() - lateral))
                    ratio = float(v[:, 2].mean()) / max(float(lateral.mean()), 1e-12)
                seen += len(new)
            target = stress if hold == "sigma3" else 3.0 * stress / (ratio + 2.0)
            self._drive_axis(2, strain_rate, length)
            for axis in (0, 1):
                self._servo_axis(axis, max(target + correction[axis], 0.0), length,
                                 relaxation, max_speed)
            n_before = len(mon.values)
            sim.run(steps=update_every)
            targets += [target] * (len(mon.values) - n_before)
            length = self.lengths
            updates += 1
            if measure_every and updates % measure_every == 0:
                meas_t.append(sim.time - t0)
                meas_e.append((l0[2] - length[2]) / l0[2])
                meas_s.append(self.measured_stress())
        # the axial walls stop; the lateral ones keep their last target
        self._drive_axis(2, 0.0, length)
        t, v = mon.arrays()
        times = np.concatenate([rec_t, np.asarray(t, dtype=float) - t0])
        vals = np.concatenate([np.asarray(rec_v), np.asarray(v, dtype=float).reshape(-1, 6)])
        target_rec = np.concatenate([[stress if hold == "sigma3" else
                                      3.0 * stress / (s0[2] / max(0.5 * (s0[0] + s0[1]),
                                                                  1e-12) + 2.0)], targets])
        return self._result(times, vals, l0, target_rec, meas_t, meas_e, meas_s,
                            {"hold": hold, "hold_stress": stress, "strain_rate": strain_rate})

    def _result(self, times, vals, l0, target, meas_t, meas_e, meas_s, extra):
        sigma, length = vals[:, :3], vals[:, 3:]
        v0 = float(np.prod(l0))
        vol = np.prod(length, axis=1)
        out = {
            "time": times, "sigma": sigma, "sigma1": sigma[:, 2], "sigma2": sigma[:, 0],
            "sigma3": sigma[:, 1], "q": sigma[:, 2] - 0.5 * (sigma[:, 0] + sigma[:, 1]),
            "p": sigma.mean(axis=1), "lengths": length, "strain": (l0 - length) / l0,
            "axial_strain": (l0[2] - length[:, 2]) / l0[2],
            "volumetric_strain": (v0 - vol) / v0,
            "void_ratio": vol / self.solid_volume() - 1.0,
            "target": np.asarray(target, dtype=float),
            "measured_time": np.asarray(meas_t, dtype=float),
            "measured_axial_strain": np.asarray(meas_e, dtype=float),
            "measured_sigma": np.asarray(meas_s, dtype=float).reshape(-1, 3, 3),
        }
        out.update(extra)
        return out


def hold_error(result, window=0.005):
    """How well a :meth:`TriaxialCell.compress` held its path: the largest deviation,
    as a fraction of the held stress, of the lateral wall stresses σ_x and σ_y from
    σ3 (``hold="sigma3"``) or of the mean stress p from its value (``hold="p"``),
    each averaged over windows of ``window`` axial strain."""
    window = _positive("window", window)
    if result.get("hold") not in HOLDS:
        raise InputError(f"result must be a TriaxialCell.compress result, got one with "
                         f"hold={result.get('hold')!r}")
    ea = np.asarray(result["axial_strain"])
    target = float(result["hold_stress"])
    if result["hold"] == "sigma3":
        s = np.asarray(result["sigma"])[:, :2]
    else:
        s = np.asarray(result["p"])[:, None]
    worst = 0.0
    edges = np.arange(0.0, ea.max() + window, window)
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (ea > a) & (ea <= b)
        if sel.sum() < 2:
            continue
        worst = max(worst, float(np.max(np.abs(s[sel].mean(axis=0) / target - 1.0))))
    return worst


def friction_angles(result, smoothing=0.005, critical_from=0.75):
    """Peak and critical-state (end) mobilised friction angles (degrees) of a
    :meth:`TriaxialCell.compress` result, from sin φ = (σ1 − σ3)/(σ1 + σ3) with σ3 the
    mean of the two lateral wall stresses, the stresses averaged over a moving window
    of ``smoothing`` axial strain. Peak: the largest value; critical state: the mean
    stresses over the records with axial strain at least ``critical_from`` × the
    final one.

    Returns
    -------
    dict: phi_peak, phi_critical (degrees), strain_at_peak, q_peak, p_at_peak,
    q_critical, p_critical (Pa), dilatancy_peak (−dε_v/dε_a at its largest, smoothed),
    volumetric_strain_end
    """
    ea = np.asarray(result["axial_strain"], dtype=float)
    if ea.size < 3:
        raise InputError(f"result must hold at least 3 records, got {ea.size}")
    smoothing = _positive("smoothing", smoothing)
    critical_from = _fraction("critical_from", critical_from, lo_open=False, hi_open=True)
    step = float(np.median(np.diff(ea)))
    window = max(1, int(round(smoothing / step))) if step > 0 else 1
    s1 = _smooth(result["sigma1"], window)
    s3 = _smooth(0.5 * (np.asarray(result["sigma2"]) + np.asarray(result["sigma3"])), window)
    sin_phi = (s1 - s3) / (s1 + s3)
    k = int(np.argmax(sin_phi))
    late = ea >= critical_from * ea[-1]
    s1c, s3c = float(s1[late].mean()), float(s3[late].mean())
    ev = _smooth(result["volumetric_strain"], window)
    rate = -np.gradient(ev, ea) if ea.size > 2 else np.zeros_like(ea)
    return {
        "phi_peak": math.degrees(math.asin(float(np.clip(sin_phi[k], -1, 1)))),
        "phi_critical": math.degrees(math.asin(float(np.clip((s1c - s3c) / (s1c + s3c),
                                                             -1, 1)))),
        "strain_at_peak": float(ea[k]), "q_peak": float(s1[k] - s3[k]),
        "p_at_peak": float((s1[k] + 2 * s3[k]) / 3), "q_critical": s1c - s3c,
        "p_critical": (s1c + 2 * s3c) / 3,
        "dilatancy_peak": float(np.max(rate[window:-window])) if ea.size > 2 * window + 1
        else float(np.max(rate)),
        "volumetric_strain_end": float(np.asarray(result["volumetric_strain"])[-1]),
    }


def _smooth(values, window):
    """Centred moving average over ``window`` records (shorter windows at the ends)."""
    v = np.asarray(values, dtype=float)
    if window <= 1 or v.size == 0:
        return v.copy()
    c = np.concatenate([[0.0], np.cumsum(v)])
    half = window // 2
    i = np.arange(v.size)
    lo = np.clip(i - half, 0, v.size)
    hi = np.clip(i + half + 1, 0, v.size)
    return (c[hi] - c[lo]) / (hi - lo)
