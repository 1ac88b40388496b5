"""Reading results back: particles, contacts, elements, energy.

:class:`Results` is the part of :class:`tdem.Simulation` that copies device state to
numpy for the user (``sim.particles.numpy()``, ``sim.contacts.numpy()``,
``sim.elements.numpy()``, ``sim.point_edge_contacts()``, ``sim.energy()``); it runs
between run segments, never inside the time loop.
"""

import numpy as np
import taichi as ti

from physics import contact_law as _claw
from physics.shapes import Superellipse

from . import state as schema
from . import step as stepk
from .neighbors import T_AX



class Results:
    """What :class:`tdem.Simulation` reads back to numpy (module docstring)."""


    # ------------------------------------------------------------------ reading
    def _particles_numpy(self, stress=True):
        """Particle state; ``stress=False`` skips the stress (computed from the contacts)."""
        if not self._built:
            self._build()
        if self.dim == 3:
            return self._particles_numpy_3d()
        if self._n == 0:
            z2 = np.zeros((0, 2))
            z = np.zeros(0)
            out = {"position": z2, "velocity": z2, "omega": z, "angle": z, "radius": z, "mass": z,
                   "force": z2, "torque": z, "displacement": z2, "id": np.zeros(0, np.int64)}
            if stress:
                out.update(stress=np.zeros((0, 2, 2)), stress_zz=z, pressure=z,
                           plastic_strain=z, strain=np.zeros((0, 3)))
            return out
        a = self._a
        prop = a["prop"].to_numpy()
        pos = a["pos"].to_numpy()
        out = {
            "position": pos, "velocity": a["vel"].to_numpy(), "omega": a["omega"].to_numpy(),
            "angle": np.degrees(a["angle"].to_numpy()),
            "radius": prop[:, 0].copy(), "mass": prop[:, 1].copy(),
            "force": a["force"].to_numpy(), "torque": a["torque"].to_numpy(),
            "displacement": pos - a["pos0"].to_numpy(),
            "id": np.concatenate(self._host["ident"]),
        }
        if stress:
            sa = self._a.get("stress_out")
            if sa is None or sa.shape[0] != self._n:
                sa = self._a["stress_out"] = ti.ndarray(ti.f64, (self._n, 3))
            stepk.particle_stress(*schema.bind(stepk.particle_stress, a, out=sa))
            s = sa.to_numpy()
            st = np.zeros((self._n, 2, 2))
            st[:, 0, 0], st[:, 1, 1] = s[:, 0], s[:, 1]
            st[:, 0, 1] = st[:, 1, 0] = s[:, 2]
            szz = np.zeros(self._n)
            out["plastic_strain"] = np.zeros(self._n)
            out["strain"] = np.zeros((self._n, 3))
            if self._cont is not None and self._cont.has_pcmm:
                c = self._cont.particle_fields()
                sel = c["pmat"] >= 0
                s4 = c["stress4"]
                st[sel, 0, 0], st[sel, 1, 1] = s4[sel, 0], s4[sel, 1]
                st[sel, 0, 1] = st[sel, 1, 0] = s4[sel, 2]
                szz[sel] = s4[sel, 3]
                out["plastic_strain"] = c["plastic_strain"]
                out["strain"] = c["strain"]
                out["failed"] = c["failed"]
                out["elements"] = c["elements"]
            out["stress"] = st
            out["stress_zz"] = szz
            out["pressure"] = -(st[:, 0, 0] + st[:, 1, 1] + szz) / 3.0
            # a disc's own stress has no out-of-plane part: its pressure is the in-plane mean
            if self._cont is None or not self._cont.has_pcmm:
                out["pressure"] = -(st[:, 0, 0] + st[:, 1, 1]) / 2.0
            else:
                dem = ~sel
                out["pressure"][dem] = -(st[dem, 0, 0] + st[dem, 1, 1]) / 2.0
        return out

    def _particles_numpy_3d(self):
        """Particle state of a 3D simulation (docs/api.md): position, velocity, omega (N, 3),
        orientation (N, 4) unit quaternions (w, x, y, z), radius, mass, force, torque
        (N, 3), displacement (N, 3)."""
        if self._n == 0:
            z3 = np.zeros((0, 3))
            z = np.zeros(0)
            return {"position": z3, "velocity": z3, "omega": z3, "orientation": np.zeros((0, 4)),
                    "radius": z, "mass": z, "force": z3, "torque": z3, "displacement": z3,
                    "id": np.zeros(0, np.int64)}
        a = self._a
        prop = a["prop"].to_numpy()
        pos = a["pos"].to_numpy()
        return {
            "position": pos, "velocity": a["vel"].to_numpy(), "omega": a["omega"].to_numpy(),
            "orientation": a["angle"].to_numpy(),
            "radius": prop[:, 0].copy(), "mass": prop[:, 1].copy(),
            "force": a["force"].to_numpy(), "torque": a["torque"].to_numpy(),
            "displacement": pos - a["pos0"].to_numpy(),
            "id": np.concatenate(self._host["ident"]),
        }

    def _contacts_numpy(self):
        """Contacts in force now: pairs (C,2) (j = -1 - wall index for walls), normal (C,)
        compression-positive, shear (C,), moment (C,) (rolling couple on the first),
        direction (C,2) the unit normal, overlap (C,), point (C,2)."""
        if not self._built:
            self._build()
        d = self.dim
        if self._n == 0:
            return {"pairs": np.zeros((0, 2), np.int64), "normal": np.zeros(0),
                    "shear": np.zeros(0), "moment": np.zeros(0),
                    "direction": np.zeros((0, d)), "overlap": np.zeros(0),
                    "point": np.zeros((0, d))}
        a = self._a
        cs = a["cs"].to_numpy()
        nbr = a["nbr"].to_numpy()
        hist = a["hist"].to_numpy()
        cn = a["cn"].to_numpy()
        pos = a["pos"].to_numpy()
        r = a["prop"].to_numpy()[:, 0]
        # in force: overlapping, or held across a gap by a law with a range
        ii, kk = np.nonzero(((cs[:, :, 2] > 0) | (cs[:, :, 0] != 0))
                            & (np.arange(self._cap)[None, :] < a["ncnt"].to_numpy()[:, None]))
        jj = nbr[ii, kk]
        u = cs[ii, kk, 2]
        normal_dir = cn[ii, kk]
        wcs = a["wcs"].to_numpy()
        wid = a["wid"].to_numpy()
        wi, wk = np.nonzero((wid >= 0) & ((wcs[:, :, 2] > 0) | (wcs[:, :, 0] != 0)))
        wu = wcs[wi, wk, 2]
        wn = a["wcn"].to_numpy()[wi, wk]
        whist = a["whist"].to_numpy()
        wcf_all = a["wcf"].to_numpy()
        if self._prims_host:
            # the primitive walls' contacts after the mesh triangles', as walls numbered
            # on from the triangles (j = -1 - (triangles + primitive index))
            pcs = a["pcs"].to_numpy()
            pi_, pk = np.nonzero((pcs[:, :, 2] > 0) | (pcs[:, :, 0] != 0))
            wid = wid.copy()
            nw = len(self._walls_host)
            wi = np.concatenate([wi, pi_])
            wk = np.concatenate([wk, wid.shape[1] + pk])
            def ext(w, p):
                return np.concatenate([w, p], axis=1)
            wid = ext(wid, np.broadcast_to(nw + np.arange(pcs.shape[1]),
                                           (len(wid), pcs.shape[1])))
            wcs = ext(wcs, pcs)
            whist = ext(whist, a["phist"].to_numpy())
            wcf_all = ext(wcf_all, a["pcf"].to_numpy())
            wu = wcs[wi, wk, 2]
            wn = np.concatenate([wn, a["pcn"].to_numpy()[pi_, pk]])
        pts = pos[ii] + self._arms(ii, normal_dir, u, r)
        wpts = pos[wi] + self._arms(wi, wn, wu, r)
        R = _claw.history_width(self._law_set)     # the rolling couple's column
        if d == 3:
            # (docs/api.md) the tangential force as a vector: the spring's 3 columns
            T = _claw.tangent_dim(3)
            cf = a["cf"].to_numpy()[ii, kk, :3]
            wcf = wcf_all[wi, wk, :3]
            fs = np.concatenate([cf + cs[ii, kk, 0][:, None] * normal_dir,
                                 wcf + wcs[wi, wk, 0][:, None] * wn])
            extra = {}
            if self._rolling3d:
                # the rolling spring's couple (a vector, on the first), after the law's
                # columns (physics.rolling.rolling_couple_3d)
                R3 = _claw.history_width(self._law_set, 3)
                extra["moment"] = np.concatenate([hist[ii, kk, R3:R3 + 3],
                                                  whist[wi, wk, R3:R3 + 3]])
            if self._polys:
                # polyhedra: the contact point is the overlap's centroid (a pair keeps
                # it from the owner in its history; against a triangle the point on the
                # triangle's plane below the centre), the overlap volume V = u l_c²
                # (l_c in the history tail)
                rows = np.concatenate(self._host["shape"])
                pp = (rows[ii, 3] < 0) | (rows[jj, 3] < 0)
                R3 = _claw.history_width(self._law_set, 3)
                pts[pp] = pos[ii[pp]] + hist[ii[pp], kk[pp], R3:R3 + 3]
                wp = rows[wi, 3] < 0
                tri0 = a["wall"].to_numpy()[wid[wi[wp], wk[wp]], T_AX:T_AX + 3]
                xw = pos[wi[wp]]
                wpts[wp] = xw + np.einsum("ij,ij->i", tri0 - xw, wn[wp])[:, None] * wn[wp]
                vol = np.where(pp, u * hist[ii, kk, R3 + 3] ** 2, 0.0)
                wvol = np.where(wp, wu * whist[wi, wk, R3] ** 2, 0.0)
                extra["volume"] = np.concatenate([vol, wvol])
            return {
                **extra,
                "pairs": np.concatenate([np.stack([ii, jj], 1),
                                         np.stack([wi, -1 - wid[wi, wk]], 1)]).astype(np.int64),
                "normal": np.concatenate([cs[ii, kk, 0], wcs[wi, wk, 0]]),
                "normal_force": np.concatenate([cs[ii, kk, 0], wcs[wi, wk, 0]]),
                "shear": np.concatenate([cs[ii, kk, 1], wcs[wi, wk, 1]]),
                "shear_force": fs,
                "direction": np.concatenate([normal_dir, wn]),
                "overlap": np.concatenate([u, wu]),
                "point": np.concatenate([pts, wpts]),
                "spring": np.concatenate([hist[ii, kk, :T], whist[wi, wk, :T]]),
            }
        return {
            "pairs": np.concatenate([np.stack([ii, jj], 1),
                                     np.stack([wi, -1 - wid[wi, wk]], 1)]).astype(np.int64),
            "normal": np.concatenate([cs[ii, kk, 0], wcs[wi, wk, 0]]),
            "shear": np.concatenate([cs[ii, kk, 1], wcs[wi, wk, 1]]),
            "moment": np.concatenate([hist[ii, kk, R], whist[wi, wk, R]]),
            "direction": np.concatenate([normal_dir, wn]),
            "overlap": np.concatenate([u, wu]),
            "point": np.concatenate([pts, wpts]),
        }

    def _arms(self, ids, n, u, r):
        """From the centres of particles ``ids`` to their contact points (outward normal
        n, overlap u): (R − u/2) n for a disc, its support point less u/2 along n for a
        shape (the midpoint of the two bodies' support points)."""
        arm = (r[ids] - 0.5 * u)[:, None] * n
        if self.dim == 3 and self._has_shapes and len(ids):
            # ellipsoids: the support point M n/h(n), less u/2 along n
            from .runner import _rotations
            rows = np.concatenate(self._host["shape"])[ids]
            ell = rows[:, 3] > 0
            if ell.any():
                rot = _rotations(self._a["angle"].to_numpy()[ids][ell])
                m = np.einsum("nij,nj,nkj->nik", rot, rows[ell, :3] ** 2, rot)
                mn = np.einsum("nij,nj->ni", m, n[ell])
                h = np.sqrt(np.einsum("ni,ni->n", n[ell], mn))
                arm[ell] = mn / h[:, None] - 0.5 * u[ell, None] * n[ell]
            return arm
        if self._has_shapes and len(ids):
            rows = np.concatenate(self._host["shape"])[ids]
            th = self._a["angle"].to_numpy()[ids]
            for key in np.unique(rows[rows[:, 2] > 0, :3], axis=0):
                sel = np.flatnonzero(np.all(rows[:, :3] == key, axis=1))
                pw = Superellipse(*key).support_world(n[sel], th[sel])
                arm[sel] = pw - 0.5 * u[sel, None] * n[sel]
        return arm

    def _image(self, d):
        """Offsets ``d`` (…, 2) to their nearest periodic image."""
        d = np.array(d, dtype=float)
        for k, span in enumerate(self._periodic):
            if span is not None:
                length = span[1] - span[0]
                d[..., k] -= length * np.round(d[..., k] / length)
        return d

    def _elements_numpy(self):
        """PCMM elements now (copies included): triangles (E, 3) of particle indices,
        owner, area, n_cover (N_e), weight (1/N_e), stress (E, 2, 2), stress_zz."""
        if not self._built:
            self._build()
        if self._cont is None or not self._cont.has_pcmm:
            return {"triangles": np.zeros((0, 3), np.int64), "owner": np.zeros(0, np.int64),
                    "area": np.zeros(0), "n_cover": np.zeros(0, np.int64),
                    "weight": np.zeros(0), "stress": np.zeros((0, 2, 2)),
                    "stress_zz": np.zeros(0)}
        return self._cont.elements()

    def measure(self, box=None, circle=None, polygon=None, sphere=None):
        """Love–Weber stress (tension-positive), porosity, coordination and fabric of the
        particles whose centres lie in a box ``((x0, y0), (x1, y1))``, a circle
        ``((cx, cy), r)`` or a polygon ``(K, 2)``; in 3D a box ``((x0, y0, z0), (x1, y1,
        z1))`` or a sphere ``((cx, cy, cz), r)`` (:mod:`tdem.measure`)."""
        from .measure import measure
        return measure(self, box=box, circle=circle, polygon=polygon, sphere=sphere)

    def point_edge_contacts(self):
        """Point–edge contacts in force now (particle–block and block–block), a dict of
        numpy arrays: point (C, 2) (particle centre or block vertex), foot (C, 2)
        (its projection on the edge), normal (C,) compression-positive, shear (C,),
        broken (C,) (cohesion and tension lost), kind (C,) 0 particle, 1 vertex."""
        self._require_built()
        pos = self._a["pos"].to_numpy() if self._n else np.zeros((0, 2))
        if self._cont is None:
            return {
                "point": np.zeros((0, 2)), "foot": np.zeros((0, 2)), "normal": np.zeros(0),
                "shear": np.zeros(0), "broken": np.zeros(0, bool), "kind": np.zeros(0, int)}
        return self._cont.point_edge_contacts(pos)

    def water_cells(self):
        """The Voronoi cells of the water of ``Fluid(voronoi=True)`` bodies
        (:mod:`physics.pcmm.cells`) at the last completed step, per particle: area (N,)
        m² per metre of thickness, pressure (N,) Pa, and water (N,) bool, the
        particles of such bodies (the others read area and pressure 0)."""
        self._require_built()
        if self._cont is None:
            z = np.zeros(self._n)
            return {"area": z, "pressure": z.copy(), "water": np.zeros(self._n, bool)}
        c = self._cont.cell_state()
        water = c["cmat"] >= 0
        return {"area": np.where(water, c["area"], 0.0),
                "pressure": np.where(water, c["pressure"], 0.0), "water": water}

    def energy(self):
        """Energy account (J per metre of thickness) at the last completed step:
        kinetic, gravitational (relative to the origin), elastic (contact springs),
        strain (PCMM elements and blocks, :meth:`tdem.continuum.Continuum.strain_energy`,
        and the core force between water or explosive particles,
        :meth:`tdem.continuum.Continuum.core_energy`),
        dissipated (damping, friction, rolling), boundary_work (done by walls and
        prescribed velocities), inflow and outflow (the energy particles brought in
        with :meth:`insert` and took out through :meth:`remove_in`: kinetic,
        gravitational and, going out, their contact springs) and total = kinetic +
        gravitational + elastic + strain + dissipated − boundary_work + outflow −
        inflow, which is conserved for DEM models; explosive: the
        internal energy Σ E·V0 of JWL particles (not in total).

        integration_error: the energy the time integration made (positive: gained)
        since the end of the first step: what the contact and element forces did to
        the bodies beyond what their springs and elements released, their friction
        and dashpots dissipated and the walls supplied, W_contacts + W_continuum +
        Δ(elastic + strain) + Δ(contact dissipation) − Δ(work of the walls), with the
        works of :meth:`work`. It is the error of the time integration (second
        order: it falls as Δt² on smooth motion), less what is dissipated without
        being booked (viscous element stresses, point–edge friction), and, for
        continua, the elements' geometric nonlinearity. The booked work runs half a
        step ahead of the stored energy; that offset, ½ Δt F·v of the last step, is
        taken out (for a linear spring the line is then zero: the leapfrog keeps its
        discrete energy exactly). kinetic and gravitational are the particles'
        (blocks' nodes are in :meth:`work`). Before the first step they are those of
        the state as given (½ m v² + ½ ω·L, −m g·x); the contact springs are first
        evaluated by the first step (elastic 0 until then)."""
        if not self._built:
            self._build()
        e = self._account_now()
        out = {k: e[k] for k in ("kinetic", "gravitational", "elastic", "strain", "dissipated",
                                 "boundary_work")}
        out["inflow"], out["outflow"] = e["inflow"], e["outflow"]
        out["total"] = out["kinetic"] + out["gravitational"] + out["elastic"] + out["strain"] \
            + out["dissipated"] - out["boundary_work"] + out["outflow"] - out["inflow"]
        out["explosive"] = self._explosive_energy()
        e0 = self._account0 if self._account0 is not None else e
        out["integration_error"] = _integration_error(e, e0)
        return out

    def work(self):
        """Work account (J per metre of thickness) since the bodies were added: the
        work each force did, booked at every step as F·(v_{n−1/2} + v_{n+1/2})/2·Δt
        (moments likewise with the spins). For the leapfrog this sums exactly to the
        change of the kinetic energy at the half steps, ½ m v_{n+1/2}² (and ½ ω·L of
        the rotation), so ``residual`` (kinetic_change − total) is round-off; for
        bodies whose spin is not along their angular momentum (tumbling ellipsoids)
        it is the rotation splitting's error, which falls with the time step.

        kinetic_change; contacts (particle pairs and walls); continuum (PCMM elements,
        point–edge contacts and non-reflecting boundaries on particles, the nodal
        forces of blocks); gravity; damping (local and global, ≤ 0); constraints
        (prescribed velocities); applied (forces of :meth:`apply_force` and block
        loads); total (their sum); residual."""
        if not self._built:
            self._build()
        e = self._account_now(strain=False)
        w = {k: e["W_" + k] for k in ("contacts", "continuum", "gravity", "damping",
                                      "constraints", "applied")}
        out = {"kinetic_change": e["ke_half"] - e["ke_start"], **w}
        out["total"] = float(sum(w.values()))
        out["residual"] = out["kinetic_change"] - out["total"]
        return out

    def _account_now(self, strain=True):
        """Every sum the energy and work accounts are made of, now (host floats);
        ``strain=False`` leaves the strain energy (the elements' pass) at 0."""
        e = dict.fromkeys(("kinetic", "gravitational", "elastic", "strain", "dissipated",
                           "boundary_work", "W_contacts", "W_continuum", "W_gravity",
                           "W_damping", "W_constraints", "W_applied", "Wp_damping",
                           "Wp_constraints",
                           "ke_half", "ke_start", "P_half"), 0.0)
        dt = self._dt_run if self._dt_run else 0.0
        a = self._a
        if self._n:
            eacc = a["eacc"].to_numpy()
            estate = a["estate"].to_numpy()
            work = a["ework"].to_numpy()
            prop = a["prop"].to_numpy()
            v = a["vel"].to_numpy()
            w = a["omega"].to_numpy()
            e["kinetic"] = float(estate[:, 0].sum())
            e["gravitational"] = float(estate[:, 1].sum())
            e["elastic"] = float(stepk.elastic_energy_sum(*schema.bind(
                stepk.elastic_energy_sum, a, laws=self._law_set, dim=self.dim)))
            if self._prims_host:
                from .primitives import elastic_energy
                e["elastic"] += float(elastic_energy(*schema.bind(elastic_energy, a,
                                                                  laws=self._law_set)))
            e["dissipated"] = float(eacc[:, 0].sum())
            if self._nbonds:
                # the bonds: their springs' energy, and what the broken ones released
                from .bonds import bond_energy
                out = ti.ndarray(ti.f64, (2,))
                bond_energy(a["bpair"], a["bprop"], a["bstate"], self._nbonds, out, self.dim)
                eb = out.to_numpy()
                e["elastic"] += float(eb[0])
                e["dissipated"] += float(eb[1])
            e["boundary_work"] = float(eacc[:, 1].sum())
            ws = work.sum(axis=0)
            for c, k in enumerate(("contacts", "continuum", "gravity", "damping",
                                   "constraints", "applied")):
                e["W_" + k] = float(ws[c])
            e["Wp_damping"], e["Wp_constraints"] = float(ws[3]), float(ws[4])
            e["ke_start"] = float(ws[6])
            w2 = w * w if w.ndim == 1 else np.einsum("ij,ij->i", w, w)
            iw2 = prop[:, 2] * w2
            if self.dim == 3 and self._has_shapes:
                # ellipsoids and polyhedra: ω·L, L the angular momentum at the half step
                # (I ω² with the scalar inertia of prop is a sphere's)
                turned = a["shp"].to_numpy()[:, 3] != 0.0
                iw2[turned] = np.einsum("ij,ij->i", w[turned], a["lmom"].to_numpy()[turned])
            e["ke_half"] = float(0.5 * np.sum(prop[:, 1] * np.einsum("ij,ij->i", v, v) + iw2))
            if self._steps == 0:
                # before the first step the step kernel has stored nothing: the state
                # at t = 0 is the particles' as given, ½ m v² + ½ ω·L and −m g·x
                e["kinetic"] = e["ke_half"]
                g = np.asarray(self.gravity, dtype=float)[:self.dim]
                e["gravitational"] = float(-np.sum(prop[:, 1] * (a["pos"].to_numpy() @ g)))
            # ½ Δt F_n·v_{n+1/2} of the contact and element forces of the last step:
            # the half step by which the booked work runs ahead of the stored energy
            f = a["force"].to_numpy()
            tq = a["torque"].to_numpy()
            tw = tq * w if w.ndim == 1 else np.einsum("ij,ij->i", tq, w)
            e["P_half"] = 0.5 * dt * float(np.sum(np.einsum("ij,ij->i", f, v) + tw))
        if self._cont is not None:
            if strain:
                e["strain"] = self._cont.strain_energy()
                if self._n:
                    # at x_n, where the kinetic energy and the contact springs are taken
                    e["strain"] += self._cont.core_energy(a["pos"].to_numpy()
                                                          - dt * a["vel"].to_numpy())
            nw, ke, ke0 = self._cont.work_sums()
            e["W_continuum"] += float(nw[0])
            e["W_gravity"] += float(nw[1])
            e["W_damping"] += float(nw[2])
            e["W_constraints"] += float(nw[3])
            e["W_applied"] += float(nw[4])
            e["ke_half"] += ke
            e["ke_start"] += ke0
            if self._cont.nv:
                ca = self._cont.a
                e["P_half"] += 0.5 * dt * float(np.sum(ca["nforce"].to_numpy()
                                                       * ca["nvel"].to_numpy()))
        # particles inserted and removed (tdem.flows): what the removed ones had booked
        # stays in the sums; the energy carried in and out is kept apart
        off = self._flow_offsets
        for k in e:
            e[k] += off.get(k, 0.0)
        for k in ("inflow", "outflow", "elastic_out"):
            e[k] = off.get(k, 0.0)
        return e

    def _explosive_energy(self):
        """Σ E_i·V0_i of the JWL particles (V0 = m/ρ0): their internal energy."""
        c = self._cont
        if c is None or not getattr(c, "has_pcmm", False) or len(c.jwl_ids) == 0:
            return 0.0
        st = c.jwl_state()[c.jwl_ids]
        return float(np.sum(st[:, 1] * st[:, 4]))


def _integration_error(e, e0):
    """ΔW_contacts + ΔW_continuum + Δ(elastic + strain) + Δ(contact dissipation) − Δ(work
    of the walls) − ΔP_half between two accounts of :meth:`Results._account_now` (the
    energy the integration made: positive when it gained); the particles' damping and
    constraint work are taken out of ``dissipated`` and ``boundary_work``."""
    def d(k):
        return e[k] - e0[k]
    contact_dissipation = d("dissipated") + d("Wp_damping")
    wall_work = d("boundary_work") - d("Wp_constraints")
    return (d("W_contacts") + d("W_continuum")) + d("elastic") + d("elastic_out") + d("strain") \
        + contact_dissipation - wall_work - d("P_half")
