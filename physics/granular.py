"""A contact law composed of sub-models, as LAMMPS's ``pair_style granular``: a normal
model, a damping model and a tangential model (and the rolling resistance of
:mod:`physics.rolling`), each one class with its parameters, combined without writing
a law::

    law = tdem.Granular(normal=tdem.granular.Hertz(young=1e8, poisson=0.3),
                        damping=tdem.granular.Restitution(0.5),
                        tangential=tdem.granular.LinearHistory(ks=2e5, friction=0.5),
                        rolling=tdem.RollingResistance(delta=0.3, model=1))

One contact is computed as the built-in laws compute it (:func:`physics.contact_law.
spring_dashpot`): the normal model gives the elastic normal force F_n and its tangent
stiffness k_n at the overlap u; the tangential model its stiffness k_s; the damping model
the normal and tangential dashpots c_n, c_s from k_n, k_s and m*; the total normal force
is F_n − c_n v_n; the tangential model turns the tangential velocity into its force
(the built-in ones: an incremental spring capped by the Coulomb limit F_n tan φ + c,
with the dashpot c_s while it sticks). ``Granular(Hooke(kn), Ratio(β),
LinearHistory(ks, μ, c))`` is :class:`physics.linear.LinearContact` and
``Granular(Hertz(E, ν), Restitution(e), Mindlin(E, ν, μ))`` is
:class:`physics.hertz_mindlin.HertzMindlin`, to the last bit.

A sub-model of one's own is a subclass of :class:`NormalModel`, :class:`DampingModel` or
:class:`TangentialModel` in a user's script, registered with :func:`register_submodel`
before the first simulation that uses ``Granular`` runs (the kernels are compiled with
the sub-models known then). Each declares ``params`` (at most :data:`WIDTHS` of its kind)
and Taichi functions (``@staticmethod`` + ``@ti.func``), with ``q`` its parameters in
``params`` order:

- normal: ``force(q, u, reff, s) -> (F_n elastic, k_n, s)`` and ``energy(q, u, reff, s)``
  (u > 0 the overlap, R* the effective radius; ``s`` one number of the contact's
  history the model may keep, e.g. the largest overlap, 0 at first contact), and
  ``critical_stiffness(radius, mass)`` on the host;
- damping: ``coefficients(q, kn, ks, meff) -> (c_n, c_s)``;
- tangential: ``stiffness(q, u, reff) -> k_s``, ``force(q, fn_el, ks, cs, vt, dt, h) ->
  (F_t, dissipated, h)`` with ``h`` the contact's history (its spring in the first T
  columns, T = 1 in 2D and 3 in 3D, turned onto the contact plane by the engine) and
  ``energy(q, ks, h, T)``, and ``critical_stiffness(radius, mass)``.

The twisting slot of LAMMPS's 3D models is not built.
"""
import math

import numpy as np
import taichi as ti

from tdem.core.errors import InputError

from .contact_law import (ContactLaw, coulomb_shear, get_columns, is_registered, put_columns,
                          register_law, shear_spring_energy)
from .hertz_mindlin import hertz_damping
from .validate import in_range, non_negative, positive

KINDS = ("normal", "damping", "tangential")
WIDTHS = {"normal": 4, "damping": 2, "tangential": 4}
_SUBMODELS = {k: [] for k in KINDS}
_USED = [False]         # a simulation with Granular has compiled its kernels


class SubModel:
    """Base of the sub-models (module docstring)."""

    kind = None
    params = ()

    def values(self):
        return [float(getattr(self, name)) for name in self.params]

    def to_dict(self):
        d = {k: v for k, v in self.__dict__.items() if not k.startswith("_")}
        d["type"] = type(self).__name__
        return d

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "type")
        return f"{type(self).__name__}({args})"


class NormalModel(SubModel):
    kind = "normal"

    def critical_stiffness(self, radius, mass):
        raise NotImplementedError(f"{type(self).__name__} must define critical_stiffness")

    def restitution_gamma(self, e):
        """γ of the dashpot c_n = γ sqrt(k_n m*) that gives this spring the restitution e
        (a linear spring's, Miyata Eq. 17, unless the model knows better)."""
        le = math.log(1.0 / e)
        return 2.0 * le / math.sqrt(math.pi ** 2 + le ** 2)


class DampingModel(SubModel):
    kind = "damping"

    def values_for(self, normal):
        """Its parameter columns beside the normal model ``normal`` (by default its
        ``values()``)."""
        return self.values()


class TangentialModel(SubModel):
    kind = "tangential"

    def critical_stiffness(self, radius, mass):
        raise NotImplementedError(f"{type(self).__name__} must define critical_stiffness")


def register_submodel(cls):
    """Register a sub-model class (usable as a decorator); returns it."""
    base = {"normal": NormalModel, "damping": DampingModel, "tangential": TangentialModel}
    kind = getattr(cls, "kind", None)
    if not (isinstance(cls, type) and kind in base and issubclass(cls, base[kind])):
        raise InputError(f"register_submodel takes a subclass of tdem.granular."
                         f"NormalModel, DampingModel or TangentialModel, got {cls!r}")
    if cls in _SUBMODELS[kind]:
        return cls
    if any(c.__name__ == cls.__name__ for c in _SUBMODELS[kind]):
        raise InputError(f"a {kind} sub-model named {cls.__name__!r} is registered already")
    if not isinstance(cls.params, tuple) or len(cls.params) > WIDTHS[kind]:
        raise InputError(f"{cls.__name__}.params must be a tuple of at most {WIDTHS[kind]} "
                         f"names, got {cls.params!r}")
    need = {"normal": ("force", "energy"), "damping": ("coefficients",),
            "tangential": ("stiffness", "force", "energy")}[kind]
    for attr in need:
        if not callable(getattr(cls, attr, None)):
            raise InputError(f"{cls.__name__}.{attr} must be a Taichi function "
                             f"(@staticmethod @ti.func)")
    if _USED[0]:
        raise InputError(f"register {cls.__name__} before the first simulation that uses "
                         f"tdem.Granular runs: its kernels are compiled with the sub-models "
                         f"known then")
    cls.code = len(_SUBMODELS[kind])
    _SUBMODELS[kind].append(cls)
    return cls


def _submodel(kind, name):
    for c in _SUBMODELS[kind]:
        if c.__name__ == name:
            return c
    raise InputError(f"no {kind} sub-model named {name!r} is registered (known: "
                     f"{[c.__name__ for c in _SUBMODELS[kind]]})")


# ------------------------------------------------------------------ built-in sub-models
@register_submodel
class Hooke(NormalModel):
    """A linear spring: F_n = k_n u (N/m; per metre in 2D)."""

    params = ("kn",)

    def __init__(self, kn):
        self.kn = positive("kn", kn)

    def critical_stiffness(self, radius, mass):
        return self.kn

    @staticmethod
    @ti.func
    def force(q, u, reff, s):
        return q[0] * u, q[0], s

    @staticmethod
    @ti.func
    def energy(q, u, reff, s):
        return 0.5 * q[0] * u * u


@register_submodel
class Hertz(NormalModel):
    """Hertz: F_n = (4/3) E* sqrt(R*) u^(3/2), k_n = 2 E* sqrt(R* u); two bodies of
    ``young`` E and ``poisson`` ν: 1/E* = 2(1 − ν²)/E."""

    params = ("e_star",)

    def __init__(self, young, poisson):
        self.young = positive("young", young)
        self.poisson = in_range("poisson", poisson, -1.0, 0.5, lo_open=True, hi_open=True)

    @property
    def e_star(self):
        return self.young / (2.0 * (1.0 - self.poisson ** 2))

    def critical_stiffness(self, radius, mass):
        # at an overlap of 5 % of the radius, R* = R/2 (as HertzMindlin)
        a = (0.5 * 0.05) ** 0.5 * np.asarray(radius, dtype=float)
        return 2.0 * self.e_star * a

    def restitution_gamma(self, e):
        return hertz_damping(e)

    @staticmethod
    @ti.func
    def force(q, u, reff, s):
        a = ti.sqrt(reff * u)
        return 4.0 / 3.0 * q[0] * a * u, 2.0 * q[0] * a, s

    @staticmethod
    @ti.func
    def energy(q, u, reff, s):
        a = ti.sqrt(reff * u)
        return 0.4 * (4.0 / 3.0 * q[0] * a * u) * u


@register_submodel
class Ratio(DampingModel):
    """Contact damping of Cundall & Strack: c_n = β k_n, c_s = β k_s."""

    params = ("beta",)

    def __init__(self, beta):
        self.beta = non_negative("beta", beta)

    @staticmethod
    @ti.func
    def coefficients(q, kn, ks, meff):
        return q[0] * kn, q[0] * ks


@register_submodel
class Restitution(DampingModel):
    """A normal dashpot c_n = γ sqrt(k_n m*) giving the restitution e (the normal model's
    γ: a linear spring's Miyata Eq. 17, Hertz's with Antypov & Elliott's factor); no
    tangential dashpot."""

    params = ("gamma",)

    def __init__(self, e):
        try:
            e = float(e)
        except (TypeError, ValueError):
            e = float("nan")
        if not 0.0 < e <= 1.0:
            raise InputError(f"restitution must lie in (0, 1], got {e!r}")
        self.e = e

    def values_for(self, normal):
        return [normal.restitution_gamma(self.e) if self.e < 1.0 else 0.0]

    @staticmethod
    @ti.func
    def coefficients(q, kn, ks, meff):
        return q[0] * ti.sqrt(kn * meff), 0.0 * ks


@register_submodel
class LinearHistory(TangentialModel):
    """An incremental spring of stiffness ``ks`` capped by the Coulomb limit
    F_n tan φ + c (``friction`` tan φ, ``cohesion`` c in N), C&S Eqs. 15–19."""

    params = ("ks", "friction", "cohesion")

    def __init__(self, ks, friction=0.5, cohesion=0.0):
        self.ks = non_negative("ks", ks)
        self.friction = non_negative("friction", friction)
        self.cohesion = non_negative("cohesion", cohesion)

    def critical_stiffness(self, radius, mass):
        return self.ks

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return q[0]

    @staticmethod
    @ti.func
    def force(q, fn_el, ks, cs, vt, dt, h):
        return _history_shear(q[1], q[2], fn_el, ks, cs, vt, dt, h)

    @staticmethod
    @ti.func
    def energy(q, ks, h, T: ti.template()):
        return shear_spring_energy(h, ks, T)


@register_submodel
class Mindlin(LinearHistory):
    """Mindlin's tangential stiffness k_s = 8 G* sqrt(R* u) (Miyata Eq. 31), used
    incrementally with the Coulomb limit as :class:`LinearHistory` (its force and
    energy); 1/G* = 2(2 − ν)/G, G = E/(2(1 + ν))."""

    params = ("g_star", "friction", "cohesion")

    def __init__(self, young, poisson, friction=0.5, cohesion=0.0):
        self.young = positive("young", young)
        self.poisson = in_range("poisson", poisson, -1.0, 0.5, lo_open=True, hi_open=True)
        self.friction = non_negative("friction", friction)
        self.cohesion = non_negative("cohesion", cohesion)

    @property
    def g_star(self):
        g = self.young / (2.0 * (1.0 + self.poisson))
        return g / (2.0 * (2.0 - self.poisson))

    def critical_stiffness(self, radius, mass):
        a = (0.5 * 0.05) ** 0.5 * np.asarray(radius, dtype=float)    # sqrt(R* u) as Hertz's
        return 8.0 * self.g_star * a

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        return 8.0 * q[0] * ti.sqrt(reff * u)


@ti.func
def _history_shear(mu, coh, fn_el, ks, cs, vt, dt, h):
    """The incremental Coulomb spring in the history's first columns (as
    :func:`physics.contact_law.spring_dashpot`)."""
    fs_old = get_columns(h, 0, ti.static(vt.n))
    fs, fs_tot, diss = coulomb_shear(fs_old + ks * vt * dt, fn_el, mu, coh, ks, cs, vt, dt,
                                     fs_old)
    h = put_columns(h, 0, fs)
    return fs_tot, diss, h


# ------------------------------------------------------------------------ the law
def _offsets():
    o, out = 3, {}
    for k in KINDS:
        out[k] = o
        o += WIDTHS[k]
    return out


OFFSET = _offsets()
STATE = 1       # the normal model's history column, after the spring (T columns)


class Granular(ContactLaw):
    """A contact law composed of a ``normal``, a ``damping`` and a ``tangential``
    sub-model and an optional ``rolling`` resistance (module docstring)."""

    params = ("normal_code", "damping_code", "tangential_code") + tuple(
        f"{k}_{c}" for k in KINDS for c in range(WIDTHS[k]))
    history = ("shear", "normal_state")
    tangential = ("shear",)

    def __init__(self, normal, tangential, damping=None, rolling=None):
        for name, v, base in (("normal", normal, NormalModel),
                              ("tangential", tangential, TangentialModel),
                              ("damping", damping, DampingModel)):
            if name == "damping" and v is None:
                continue
            if not isinstance(v, base) or type(v) not in _SUBMODELS[base.kind]:
                raise InputError(f"Granular: {name} must be a registered {base.kind} "
                                 f"sub-model (tdem.granular.*), got {v!r}")
        if not is_registered(Granular):
            register_law(Granular)
        self.normal = normal
        self.tangential = tangential
        self.damping = damping if damping is not None else Ratio(0.0)
        self._set_rolling(rolling)

    @property
    def hertzian(self):
        return isinstance(self.normal, Hertz)

    def values(self):
        out = [float(type(m).code) for m in (self.normal, self.damping, self.tangential)]
        for kind in KINDS:
            m = getattr(self, kind)
            v = m.values_for(self.normal) if kind == "damping" else m.values()
            out += v + [0.0] * (WIDTHS[kind] - len(v))
        return out

    def row(self, width=None):
        _USED[0] = True
        return super().row(width)

    def critical_stiffness(self, radius, mass):
        return np.maximum(*self.critical_stiffnesses(radius, mass))

    def critical_stiffnesses(self, radius, mass):
        return (self.normal.critical_stiffness(radius, mass),
                self.tangential.critical_stiffness(radius, mass))

    def update(self, **params):
        raise InputError("Granular: change a sub-model by making the law anew "
                         "(tdem.Granular(normal=..., ...))")

    def to_dict(self):
        d = {"type": "Granular"}
        for kind in KINDS:
            d[kind] = getattr(self, kind).to_dict()
        if self.rolling is not None:
            d["rolling"] = self.rolling.to_dict()
        return d

    @classmethod
    def _from_parts(cls, d):
        from .rolling import RollingResistance

        parts = {}
        for kind in KINDS:
            p = dict(d[kind])
            sub = _submodel(kind, p.pop("type"))
            if sub is Restitution:
                obj = Restitution(p["e"])
            else:
                obj = sub.__new__(sub)
                obj.__dict__.update(p)
            parts[kind] = obj
        rolling = RollingResistance(**d["rolling"]) if "rolling" in d else None
        return cls(rolling=rolling, **parts)

    def __repr__(self):
        return (f"Granular(normal={self.normal!r}, damping={self.damping!r}, "
                f"tangential={self.tangential!r}, rolling={self.rolling!r})")

    # ------------------------------------------------------------------ kernels
    @staticmethod
    @ti.func
    def _q(q, kind: ti.template()):
        return ti.Vector([q[ti.static(OFFSET[kind]) + c]
                          for c in ti.static(range(WIDTHS[kind]))])

    @staticmethod
    @ti.func
    def _normal(q, u, reff, s):
        qn = Granular._q(q, "normal")
        code = ti.cast(q[0], ti.i32)
        fn_el = 0.0
        kn = 0.0
        s_out = s
        for c in ti.static(range(len(_SUBMODELS["normal"]))):
            if code == c:
                fn_el, kn, s_out = ti.static(_SUBMODELS["normal"][c].force)(qn, u, reff, s)
        return fn_el, kn, s_out

    @staticmethod
    @ti.func
    def _tangential_stiffness(q, u, reff):
        qt = Granular._q(q, "tangential")
        code = ti.cast(q[2], ti.i32)
        ks = 0.0
        for c in ti.static(range(len(_SUBMODELS["tangential"]))):
            if code == c:
                ks = ti.static(_SUBMODELS["tangential"][c].stiffness)(qt, u, reff)
        return ks

    @staticmethod
    @ti.func
    def force(q, u, vn, vt, meff, reff, dt, h):
        T = ti.static(vt.n)
        fn_el, kn, s = Granular._normal(q, u, reff, h[T])
        ks = Granular._tangential_stiffness(q, u, reff)
        qd = Granular._q(q, "damping")
        cd = ti.cast(q[1], ti.i32)
        cn = 0.0
        cs = 0.0
        for c in ti.static(range(len(_SUBMODELS["damping"]))):
            if cd == c:
                cn, cs = ti.static(_SUBMODELS["damping"][c].coefficients)(qd, kn, ks, meff)
        fn = fn_el - cn * vn
        qt = Granular._q(q, "tangential")
        ct = ti.cast(q[2], ti.i32)
        ft = vt * 0.0
        diss = 0.0
        hout = h
        for c in ti.static(range(len(_SUBMODELS["tangential"]))):
            if ct == c:
                ft, diss, hout = ti.static(_SUBMODELS["tangential"][c].force)(
                    qt, fn_el, ks, cs, vt, dt, h)
        diss += cn * vn * vn * dt
        hout[T] = s
        return fn_el, fn, ft, kn, cn, diss, hout

    @staticmethod
    @ti.func
    def energy(q, u, reff, h, T: ti.template()):
        qn = Granular._q(q, "normal")
        cn = ti.cast(q[0], ti.i32)
        e = 0.0
        for c in ti.static(range(len(_SUBMODELS["normal"]))):
            if cn == c:
                e = ti.static(_SUBMODELS["normal"][c].energy)(qn, u, reff, h[T])
        ks = Granular._tangential_stiffness(q, u, reff)
        qt = Granular._q(q, "tangential")
        ct = ti.cast(q[2], ti.i32)
        for c in ti.static(range(len(_SUBMODELS["tangential"]))):
            if ct == c:
                e += ti.static(_SUBMODELS["tangential"][c].energy)(qt, ks, h, T)
        return e

    @staticmethod
    @ti.func
    def stiffness(q, u, reff):
        fn_el, kn, s = Granular._normal(q, u, reff, 0.0)
        return kn
