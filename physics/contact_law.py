"""The contact-law table shared by all laws, and the dispatch for one contact.

Every law is packed into one row of floats so that the engine's kernels can read
any law from one array. Columns:

====  ==========================================================
0     law type: 0 linear (Cundall & Strack), 1 Hertz–Mindlin
1     k_n (linear) or E* (Hertz)
2     k_s (linear) or G* (Hertz)
3     friction coefficient tan(phi_mu)
4     cohesion c (force, N) in the Coulomb limit
5     beta: contact damping c_n = beta k_n, c_s = beta k_s (C&S Eq. 28)
6     gamma_e = 2 ln(1/e)/sqrt(pi^2 + ln^2 e): c_n = gamma_e sqrt(k_n m*)
7     rolling resistance delta (B = delta r_bar), 0 = off
8     rolling model (1 elastic-perfectly plastic, 2 elastic-brittle)
9     rolling damping on (1) or off (0)
====  ==========================================================
"""
import math

import taichi as ti

from tdem.errors import InputError

from .rolling import RollingResistance
from .validate import non_negative

LAW_WIDTH = 12
LINEAR, HERTZ = 0, 1


class ContactLaw:
    """Base class of particle–particle and particle–wall contact laws."""

    rolling = None

    def row(self):
        raise NotImplementedError

    def critical_stiffness(self, radius, mass):
        """Largest stiffness the law reaches for particles of this radius and mass
        (numbers or numpy arrays), for the critical time step."""
        raise NotImplementedError

    def update(self, **params):
        """Change parameters, validated as in the constructor (e.g.
        ``law.update(friction=0.0)``). A simulation using the law takes the new values
        at its next ``run``. Nothing changes if a value is bad."""
        current = {k: v for k, v in self.to_dict().items() if k != "type"}
        if self.rolling is not None:
            current["rolling"] = self.rolling
        unknown = set(params) - set(current) - {"rolling"}
        if unknown:
            raise InputError(f"{type(self).__name__} has no parameter {sorted(unknown)[0]!r}")
        fresh = type(self)(**{**current, **params})
        self.__dict__.update(fresh.__dict__)
        return self

    def _set_common(self, friction, cohesion, restitution, damping_ratio, rolling):
        """Friction, cohesion and damping shared by every law, validated."""
        self.friction = non_negative("friction", friction)
        self.cohesion = non_negative("cohesion", cohesion)
        self.damping_ratio = non_negative("damping_ratio", damping_ratio)
        self._gamma = 0.0
        self.restitution = None
        if restitution is not None:
            try:
                e = float(restitution)
            except (TypeError, ValueError):
                e = float("nan")
            if not 0.0 < e <= 1.0:
                raise InputError(f"restitution must lie in (0, 1], got {restitution!r}")
            self.restitution = e
            if e < 1.0:
                le = math.log(1.0 / e)
                self._gamma = 2.0 * le / math.sqrt(math.pi ** 2 + le ** 2)
        if rolling is not None and not isinstance(rolling, RollingResistance):
            raise InputError(f"rolling must be a tdem.RollingResistance or None, "
                             f"got {rolling!r}")
        self.rolling = rolling

    def _rolling_columns(self):
        r = self.rolling
        if r is None:
            return [0.0, 0.0, 0.0]
        return [r.delta, float(r.model), 1.0 if r.damping else 0.0]

    def to_dict(self):
        d = {k: v for k, v in self.__dict__.items() if not k.startswith("_") and k != "rolling"}
        d["type"] = type(self).__name__
        if self.rolling is not None:
            d["rolling"] = self.rolling.to_dict()
        return d

    @staticmethod
    def from_dict(d):
        from .hertz_mindlin import HertzMindlin
        from .linear import LinearContact
        d = dict(d)
        cls = {"LinearContact": LinearContact, "HertzMindlin": HertzMindlin}[d.pop("type")]
        if "rolling" in d:
            d["rolling"] = RollingResistance(**d["rolling"])
        return cls(**d)

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "type")
        return f"{type(self).__name__}({args})"


@ti.func
def coulomb_shear(fs_trial, fn_el, mu, coh, ks, cs, vs, dt, fs_old):
    """Coulomb limit |F_s| <= F_n tan(phi) + c (C&S Eq. 19), keeping the sign.

    Returns (spring force kept, total shear force, dissipated energy). The shear
    dashpot is off while sliding (C&S). The slip energy is the mean of the old and
    new shear force times the slip increment (F_trial − F_s)/k_s, which is what the
    central-difference step does on the spring (with F_max alone the account loses
    an O(Δt) share whenever F_n changes while sliding).
    """
    fmax = ti.max(fn_el * mu + coh, 0.0)
    fs = fs_trial
    fs_tot = 0.0
    diss = 0.0
    if ti.abs(fs_trial) > fmax:
        fs = ti.math.sign(fs_trial) * fmax
        fs_tot = fs
        if ks > 0.0:
            diss = 0.5 * (fs_old + fs) * (fs_trial - fs) / ks
    else:
        fs_tot = fs + cs * vs
        diss = cs * vs * vs * dt
    return fs, fs_tot, diss


@ti.func
def pair_force(lawp: ti.template(), L, u, vn, vs, meff, reff, dt, fs_old):
    """Forces of one contact in its local frame (n from i to j, t = n rotated +90°).

    u: overlap (> 0), vn, vs: relative velocity of j w.r.t. i along n and t,
    meff: m* (m_i for a wall), reff: R* = R_i R_j/(R_i+R_j) (R_i for a wall).
    Returns (F_n elastic, F_n total, F_s spring, F_s total, tangent k_n, c_n, dissipation),
    F_n compression-positive.
    """
    kind = ti.cast(lawp[L, 0], ti.i32)
    fn_el = 0.0
    kn = 0.0
    ks = 0.0
    if kind == LINEAR:
        kn = lawp[L, 1]
        ks = lawp[L, 2]
        fn_el = kn * u
    else:
        # Hertz (Miyata Eqs. 24, 27, 31): a = sqrt(R* u)
        a = ti.sqrt(reff * u)
        fn_el = 4.0 / 3.0 * lawp[L, 1] * a * u
        kn = 2.0 * lawp[L, 1] * a
        ks = 8.0 * lawp[L, 2] * a
    beta = lawp[L, 5]
    cn = beta * kn + lawp[L, 6] * ti.sqrt(kn * meff)
    cs = beta * ks
    fn = fn_el - cn * vn
    fs, fs_tot, diss = coulomb_shear(fs_old + ks * vs * dt, fn_el, lawp[L, 3], lawp[L, 4],
                                     ks, cs, vs, dt, fs_old)
    diss += cn * vn * vn * dt
    return fn_el, fn, fs, fs_tot, kn, cn, diss


@ti.func
def elastic_energy(lawp: ti.template(), L, u, reff, fs, moment, rbar):
    """Energy stored in the springs of one contact (normal, shear, rolling)."""
    kind = ti.cast(lawp[L, 0], ti.i32)
    e = 0.0
    kn = 0.0
    ks = 0.0
    if kind == LINEAR:
        kn = lawp[L, 1]
        ks = lawp[L, 2]
        e = 0.5 * kn * u * u
    else:
        a = ti.sqrt(reff * u)
        kn = 2.0 * lawp[L, 1] * a
        ks = 8.0 * lawp[L, 2] * a
        e = 0.4 * (4.0 / 3.0 * lawp[L, 1] * a * u) * u
    if ks > 0.0:
        e += 0.5 * fs * fs / ks
    delta = lawp[L, 7]
    if delta > 0.0 and kn > 0.0:
        b = delta * rbar
        km = kn * b * b / 12.0
        e += 0.5 * moment * moment / km
    return e
