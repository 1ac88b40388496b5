"""Contact laws: the base class, the registry, and the dispatch for one contact.

A contact is computed in three parts (Yade's geometry → physics → law functors):
the geometry function of the shape pair (:mod:`physics.geometry`) gives the overlap
``u``, the normal and the relative velocity; the contact law turns them and the law's
own history columns into forces, a tangent stiffness and the dissipated energy; the
engine adds rolling resistance (:mod:`physics.rolling`) and accumulates the forces.

A law is a subclass of :class:`ContactLaw` in a file of its own (the built-in ones:
:mod:`physics.linear`, :mod:`physics.hertz_mindlin`), registered once with
:func:`register_law`. It declares

- ``params``: the names of its parameter columns, in order; :meth:`ContactLaw.values`
  gives their numbers (by default the attributes of those names);
- ``history``: the names of its history columns (kept per contact, carried across
  neighbour rebuilds, snapshots and checkpoints); the first is by convention the
  tangential spring force that the energy account and output read;
- ``tangential``: the names in ``history`` that are vectors of the tangent plane
  (``T`` columns each: 1 in 2D, where the tangent plane is the line along
  t = n rotated +90°, and 3 in 3D); the other columns are scalars. The built-in laws
  declare ``tangential = ("shear",)``;
- ``force``, ``energy`` and ``stiffness``: Taichi functions (``@staticmethod`` + ``@ti.func``)::

      force(q, u, vn, vt, meff, reff, dt, h) -> (fn_el, fn, ft, kn, cn, diss, h)
      energy(q, u, reff, h, T: ti.template()) -> stored elastic energy
      stiffness(q, u, reff) -> tangent normal stiffness k_n (for the rolling spring)

  with ``q`` the vector of the parameters in ``params`` order, ``u`` > 0 the overlap,
  ``vn`` the relative velocity of the partner along the normal and ``vt`` its
  tangential part (a ``ti.Vector`` of ``T`` components, :mod:`physics.geometry.frame`),
  ``meff`` the effective mass m* (m_i against a wall), ``reff`` the effective radius
  R* (R_i against a wall), ``h`` the contact's history vector (the law's columns
  first, in ``history`` order, a tangential one taking ``T`` columns; it returns it
  updated). It returns the elastic normal force ``fn_el`` and the total ``fn`` (both
  compression-positive), the total tangential force ``ft`` (a vector like ``vt``),
  the tangent normal stiffness ``kn`` and normal dashpot ``cn`` (rolling resistance
  and the critical time step use them) and the energy dissipated in the step.
  :func:`get_columns` and :func:`put_columns` read and write a vector column. The
  laws are thus written once for 2D and 3D: the engine's geometry function of the
  shape pair gives ``n``, ``u`` and the relative velocity, and the frame functions
  split it into ``vn`` and ``vt`` and turn ``ft`` back into a force.
- ``range`` (optional): the name of one of its ``params`` that gives the distance
  across which the law acts (m). Between discs and spheres such a law is also called
  while the two are apart by less than that gap, with ``u`` = −gap ≤ 0 (and the
  normal, arms and relative velocity of the frame at that distance); it decides
  itself what acts there (its history tells it, e.g., whether a liquid bridge has
  formed) and returns zero forces where nothing does. Beyond the range the contact's
  history is cleared. The neighbour lists reach that much further, and
  ``energy`` is called for such pairs too. Against segment walls and sphere–mesh
  contacts the same holds (R* = R_i). A law without a range is called only while ``u``
  > 0.

A law defined in a user's script is registered and used exactly like a built-in one
(no edit of the package); kernels compiled before a registration are recompiled for
simulations built after it.

The parameter table (one row per law used by a simulation, ``lawp``) has the columns

====  ==========================================================
0     law code (index in the registry)
1     rolling resistance delta (B = delta r_bar), 0 = off   (:mod:`physics.rolling`)
2     rolling model (1 elastic-perfectly plastic, 2 elastic-brittle Eq. 36, 3 the same
      with a permanent break)
3     rolling damping on (1) or off (0)
4     the law's range (m; 0: it acts only while the particles overlap)
5…    the law's ``params``
====  ==========================================================

and each contact slot's history vector holds the law's columns first, then the
rolling couple, rotation and broken flag (:data:`ROLLING_COLUMNS`), then, for pairs
of particles, the overlap offset of a pair that left the PCMM elements (``u0``, the
last column).
"""
import math

import taichi as ti

from tdem.core.errors import InputError

from .rolling import COL_ROLL_DAMP, RollingResistance
from .validate import non_negative

# columns of a row of the law table (the rolling ones are physics.rolling's)
COL_CODE = 0
COL_REACH = COL_ROLL_DAMP + 1      # the law's range (m): it acts across gaps below it
COL_PARAMS = COL_REACH + 1
ROLLING_COLUMNS = ("moment", "rotation", "broken")

_REGISTRY = []           # law classes; a class's code is its index
_BY_NAME = {}
# built-in laws registered when first made (their history columns would widen every
# simulation's contacts): name → module
_ON_FIRST_USE = {"WetContact": "physics.wet_contact", "Granular": "physics.granular"}


def register_law(cls):
    """Register a contact law class (usable as a decorator); returns it.

    The class must subclass :class:`ContactLaw` and declare ``params``, ``history``,
    ``force``, ``energy`` and ``stiffness`` (module docstring). Registering the same class again does
    nothing; another class of a registered name is refused."""
    if not (isinstance(cls, type) and issubclass(cls, ContactLaw)):
        raise InputError(f"register_law takes a subclass of tdem.ContactLaw, got {cls!r}")
    name = cls.__name__
    known = _BY_NAME.get(name)
    if known is cls:
        return cls
    if known is not None:
        raise InputError(f"a contact law named {name!r} is registered already ({known!r})")
    for attr in ("params", "history"):
        v = getattr(cls, attr, None)
        if not isinstance(v, tuple) or not all(isinstance(s, str) for s in v):
            raise InputError(f"{name}.{attr} must be a tuple of column names, got {v!r}")
    if len(cls.history) < 1:
        raise InputError(f"{name}.history must name at least the tangential spring column")
    reach = getattr(cls, "range", None)
    if reach is not None and reach not in cls.params:
        raise InputError(f"{name}.range must name one of its params {cls.params} (the "
                         f"distance in metres across which it acts), got {reach!r}")
    tang = getattr(cls, "tangential", ())
    if not isinstance(tang, tuple) or not set(tang) <= set(cls.history):
        raise InputError(f"{name}.tangential must be a tuple of names in its history "
                         f"{cls.history}, got {tang!r}")
    for attr in ("force", "energy", "stiffness"):
        if not callable(getattr(cls, attr, None)):
            raise InputError(f"{name}.{attr} must be a Taichi function (@staticmethod @ti.func)")
    cls.code = len(_REGISTRY)
    _REGISTRY.append(cls)
    _BY_NAME[name] = cls
    return cls


def unregister_law(cls):
    """Take back the most recent registration, ``cls`` (for tests and notebooks that
    define a law for a while). Simulations built while it was registered keep it."""
    if not _REGISTRY or _REGISTRY[-1] is not cls or cls.__module__.startswith("physics."):
        raise InputError(f"only the most recently registered law can be unregistered, "
                         f"not {cls!r}")
    _REGISTRY.pop()
    del _BY_NAME[cls.__name__]


def registered():
    """The registered law classes now, as a tuple (the kernels' template argument: a
    simulation keeps the tuple of the time it was built)."""
    return tuple(_REGISTRY)


def is_registered(cls):
    return _BY_NAME.get(cls.__name__) is cls


def law_class(name):
    """The registered law class of this name."""
    if name not in _BY_NAME and name in _ON_FIRST_USE:
        import importlib

        cls = getattr(importlib.import_module(_ON_FIRST_USE[name]), name)
        register_law(cls)
    try:
        return _BY_NAME[name]
    except KeyError:
        raise InputError(f"no contact law named {name!r} is registered (known: "
                         f"{sorted(_BY_NAME)}); register it with tdem.register_law "
                         f"before loading") from None


# components of a tangent-plane vector: 1 in 2D (along t), 3 in 3D
TANGENT_2D = 1
TANGENT_3D = 3


def tangent_dim(dim):
    """Components of a tangent-plane vector in ``dim`` dimensions."""
    return TANGENT_2D if dim == 2 else TANGENT_3D


def history_columns(cls, tdim=TANGENT_2D):
    """{name: (first column, width)} of a law class's history columns, a tangential one
    ``tdim`` wide."""
    out, c = {}, 0
    for name in cls.history:
        w = tdim if name in getattr(cls, "tangential", ()) else 1
        out[name] = (c, w)
        c += w
    return out


def history_width(laws, tdim=TANGENT_2D):
    """Number of history columns the laws of ``laws`` own (the widest)."""
    return max(sum(w for _, w in history_columns(c, tdim).values()) for c in laws)


# the columns after the rolling ones: a pair's overlap offset u0 (PCMM hand-over), then
# for shaped particles the normal angle of the last step (a warm start) and the pair's
# state (> 0: touching, its R*; −1: tracked, apart; 0: not tracked); a wall contact of
# a shaped particle keeps its state (> 0: touching, its R*)
PAIR_TAIL = ("u0", "normal_angle", "shape_state")
WALL_TAIL = ("shape_state",)


def pair_history_width(laws, tdim=TANGENT_2D):
    """Width of a particle pair's history vector: law columns, rolling, PAIR_TAIL (in
    3D the law columns only: rolling, the PCMM hand-over and shapes are 2D)."""
    if tdim == TANGENT_3D:
        return history_width(laws, tdim)
    return history_width(laws, tdim) + len(ROLLING_COLUMNS) + len(PAIR_TAIL)


def wall_history_width(laws, tdim=TANGENT_2D):
    """Width of a particle–wall history vector: law columns, rolling, WALL_TAIL (in 3D
    the law columns only)."""
    if tdim == TANGENT_3D:
        return history_width(laws, tdim)
    return history_width(laws, tdim) + len(ROLLING_COLUMNS) + len(WALL_TAIL)


def table_width(laws):
    return COL_PARAMS + max(len(c.params) for c in laws)


class ContactLaw:
    """Base class of particle–particle and particle–wall contact laws (module
    docstring: what a subclass declares)."""

    params = ()
    history = ()
    tangential = ()
    rolling = None
    range = None         # the name of the param that gives the law's range (m), if any
    #: its normal stiffness grows as sqrt(overlap) (Hertz): the runner checks after a
    #: run that the step still suits the largest overlap
    hertzian = False

    def acting_range(self):
        """The distance (m) across which the law acts: the value of the param that
        ``range`` names, 0 for a law that acts only while the particles overlap."""
        name = type(self).range
        if name is None:
            return 0.0
        v = self.values()[type(self).params.index(name)]
        if not (v >= 0.0 and math.isfinite(v)):
            raise InputError(f"{type(self).__name__}: its range {name!r} must be a "
                             f"distance >= 0, got {v!r}")
        return v

    def values(self):
        """Numbers of the parameter columns, in ``params`` order."""
        return [float(getattr(self, name)) for name in self.params]

    def row(self, width=None):
        """This law's row of the parameter table."""
        cls = type(self)
        if not is_registered(cls):
            raise InputError(f"contact law {cls.__name__} is not registered: decorate it "
                             f"with @tdem.register_law")
        vals = self.values()
        if len(vals) != len(cls.params):
            raise InputError(f"{cls.__name__}.values() gave {len(vals)} numbers for the "
                             f"{len(cls.params)} params {cls.params}")
        r = [float(cls.code)] + self._rolling_columns() + [self.acting_range()] + vals
        if width is not None:
            r += [0.0] * (width - len(r))
        return r

    def critical_stiffness(self, radius, mass):
        """Largest stiffness the law reaches for particles of this radius and mass
        (numbers or numpy arrays), for the critical time step."""
        raise NotImplementedError(f"{type(self).__name__} must define critical_stiffness")

    def critical_stiffnesses(self, radius, mass):
        """(normal, shear) stiffness the law reaches for particles of this radius and
        mass, for the stable step of a dense packing (:mod:`physics.stability`); by
        default both the :meth:`critical_stiffness` (an upper bound)."""
        k = self.critical_stiffness(radius, mass)
        return k, k

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
        """Friction, cohesion and damping shared by the built-in laws, validated."""
        self.friction = non_negative("friction", friction)
        if self.friction > 10.0:
            raise InputError(f"friction is the coefficient mu = tan(phi), at most 10, got "
                             f"{friction!r} (an angle in degrees? tan({friction!r}°) = "
                             f"{math.tan(math.radians(min(self.friction, 89.9))):.3g})")
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
        self._set_rolling(rolling)

    def _set_rolling(self, rolling):
        if rolling is not None and not isinstance(rolling, RollingResistance):
            raise InputError(f"rolling must be a tdem.RollingResistance or None, "
                             f"got {rolling!r}")
        self.rolling = rolling

    def _rolling_columns(self):
        r = self.rolling
        if r is None:
            return [0.0, 0.0, 0.0]
        return [r.delta, r.column(), 1.0 if r.damping else 0.0]

    def to_dict(self):
        """The constructor's arguments (and ``type``, the class name)."""
        d = {k: v for k, v in self.__dict__.items() if not k.startswith("_") and k != "rolling"}
        d["type"] = type(self).__name__
        if self.rolling is not None:
            d["rolling"] = self.rolling.to_dict()
        return d

    @staticmethod
    def from_dict(d):
        d = dict(d)
        cls = law_class(d.pop("type"))
        if hasattr(cls, "_from_parts"):        # a law made of other objects
            return cls._from_parts(d)
        if "rolling" in d:
            d["rolling"] = RollingResistance(**d["rolling"])
        return cls(**d)

    def __repr__(self):
        args = ", ".join(f"{k}={v!r}" for k, v in self.to_dict().items() if k != "type")
        return f"{type(self).__name__}({args})"


# ------------------------------------------------------------- shared pieces of laws
@ti.func
def get_columns(h, first: ti.template(), width: ti.template()):
    """Columns first … first + width − 1 of the history vector h, as a vector."""
    return ti.Vector([h[first + c] for c in ti.static(range(width))])


@ti.func
def put_columns(h, first: ti.template(), v):
    """h with the vector v written into its columns from ``first``; returns h."""
    for c in ti.static(range(v.n)):
        h[first + c] = v[c]
    return h


@ti.func
def coulomb_shear(fs_trial, fn_el, mu, coh, ks, cs, vs, dt, fs_old):
    """Coulomb limit |F_s| <= F_n tan(phi) + c (C&S Eq. 19), keeping the direction.

    ``fs_trial``, ``vs`` and ``fs_old`` are tangent-plane vectors (one component in
    2D, three in 3D). Returns (spring force kept, total shear force, dissipated
    energy). The shear dashpot is off while sliding (C&S). The slip energy is the
    mean of the old and new shear force times the slip increment (F_trial − F_s)/k_s,
    which is what the central-difference step does on the spring (with F_max alone
    the account loses an O(Δt) share whenever F_n changes while sliding).
    """
    fmax = ti.max(fn_el * mu + coh, 0.0)
    fs = fs_trial
    fs_tot = fs_trial * 0.0
    diss = 0.0
    # |F_trial| > F_max compared in squares: the square root only where it slides
    mag2 = fs_trial.dot(fs_trial)
    if mag2 > fmax * fmax:
        if ti.static(fs_trial.n == 1):
            fs = ti.Vector([ti.math.sign(fs_trial[0]) * fmax])
        else:
            fs = fs_trial * (fmax / ti.sqrt(mag2))
        fs_tot = fs
        if ks > 0.0:
            diss = (0.5 * (fs_old + fs)).dot(fs_trial - fs) / ks
    else:
        fs_tot = fs + cs * vs
        diss = (cs * vs).dot(vs) * dt
    return fs, fs_tot, diss


@ti.func
def spring_dashpot(fn_el, kn, ks, beta, gamma, u, vn, vs, meff, mu, coh, dt, h):
    """Normal dashpot c_n = β k_n + γ_e sqrt(k_n m*) and the incremental Coulomb
    shear spring (a tangent-plane vector in the history's first columns), shared by
    the linear and Hertz–Mindlin laws. Returns the tuple of :meth:`ContactLaw.force`."""
    cn = beta * kn + gamma * ti.sqrt(kn * meff)
    cs = beta * ks
    fn = fn_el - cn * vn
    fs_old = get_columns(h, 0, ti.static(vs.n))
    fs, fs_tot, diss = coulomb_shear(fs_old + ks * vs * dt, fn_el, mu, coh, ks, cs, vs, dt,
                                     fs_old)
    diss += cn * vn * vn * dt
    h = put_columns(h, 0, fs)
    return fn_el, fn, fs_tot, kn, cn, diss, h


@ti.func
def shear_spring_energy(h, ks, T: ti.template()):
    """0.5 |F_s|²/k_s of the shear spring in the history's first T columns."""
    e = 0.0
    if ks > 0.0:
        fs = get_columns(h, 0, T)
        e = 0.5 * fs.dot(fs) / ks
    return e


# ------------------------------------------------------------------- dispatch
@ti.func
def _params(laws: ti.template(), c: ti.template(), lawp: ti.template(), L):
    return ti.Vector([lawp[L, COL_PARAMS + j] for j in ti.static(range(len(laws[c].params)))])


@ti.func
def law_force(laws: ti.template(), lawp: ti.template(), L, u, vn, vt, meff, reff, dt, h):
    """Forces of one contact by the law of row L of the table (module docstring), in
    the contact's frame (n from i to j; vt in the tangent plane). Returns
    (F_n elastic, F_n total, F_t total (a vector like vt), tangent k_n, c_n,
    dissipation, history)."""
    code = ti.cast(lawp[L, COL_CODE], ti.i32)
    fn_el = 0.0
    fn = 0.0
    fs_tot = vt * 0.0
    kn = 0.0
    cn = 0.0
    diss = 0.0
    hout = h
    for c in ti.static(range(len(laws))):
        if code == c:
            q = _params(laws, c, lawp, L)
            fn_el, fn, fs_tot, kn, cn, diss, hout = ti.static(laws[c].force)(
                q, u, vn, vt, meff, reff, dt, h)
    return fn_el, fn, fs_tot, kn, cn, diss, hout


@ti.func
def law_energy(laws: ti.template(), lawp: ti.template(), L, u, reff, h, T: ti.template()):
    """Energy stored in the normal and tangential springs of one contact (T: the
    components of a tangent-plane vector)."""
    code = ti.cast(lawp[L, COL_CODE], ti.i32)
    e = 0.0
    for c in ti.static(range(len(laws))):
        if code == c:
            q = _params(laws, c, lawp, L)
            e = ti.static(laws[c].energy)(q, u, reff, h, T)
    return e


@ti.func
def law_stiffness(laws: ti.template(), lawp: ti.template(), L, u, reff):
    """Tangent normal stiffness of one contact (the rolling spring's energy needs it)."""
    code = ti.cast(lawp[L, COL_CODE], ti.i32)
    kn = 0.0
    for c in ti.static(range(len(laws))):
        if code == c:
            q = _params(laws, c, lawp, L)
            kn = ti.static(laws[c].stiffness)(q, u, reff)
    return kn


@ti.func
def zero_history(h):
    """The history vector h with every column 0 (whatever its width)."""
    for c in ti.static(range(h.n)):
        h[c] = 0.0
    return h


def remap_history(h, width, tail):
    """History array ``h`` (…, w) with ``width`` columns: the law columns (the first
    w − tail) are kept, cut or padded with zeros; the last ``tail`` columns (rolling,
    u0) stay last. A pair history of 4 columns, written before the overlap offset u0
    existed, gets u0 = 0."""
    import numpy as np

    h = np.asarray(h)
    if tail == 4 and h.shape[-1] == 4:
        h = np.concatenate([h, np.zeros(h.shape[:-1] + (1,))], axis=-1)
    if h.shape[-1] == width:
        return h
    nlaw_old = h.shape[-1] - tail
    nlaw = width - tail
    out = np.zeros(h.shape[:-1] + (width,), dtype=h.dtype)
    keep = min(nlaw_old, nlaw)
    out[..., :keep] = h[..., :keep]
    out[..., nlaw:] = h[..., nlaw_old:]
    return out


def tangential_firsts(cls):
    """First columns (3D) of a law class's tangent-plane history columns."""
    cols = history_columns(cls, TANGENT_3D)
    return tuple(cols[name][0] for name in getattr(cls, "tangential", ()))


@ti.func
def _turned(h, first: ti.template(), n):
    """h with its tangent-plane column at ``first`` (3D) turned onto the plane normal
    to n, its magnitude kept."""
    v = get_columns(h, first, 3)
    m2 = v.dot(v)
    if m2 > 0.0:
        vn = v.dot(n)
        p = v - vn * n
        # |p|² = m2 (1 − x) with x = (v·n)²/m2, so the length is restored by
        # (1 − x)^(−1/2). Between steps the plane turns little and x is tiny; below
        # 1e-6 the series 1 + x/2 + 3x²/8 is that factor to round-off (the next
        # term, 5x³/16, is below 4e-19), without a division and a square root.
        x = vn * vn / m2
        if x < 1e-6:
            p *= 1.0 + x * (0.5 + 0.375 * x)
        else:
            p2 = p.dot(p)
            if p2 > 0.0:
                p *= ti.sqrt(m2 / p2)
        h = put_columns(h, first, p)
    return h


@ti.func
def rotate_tangential(laws: ti.template(), lawp: ti.template(), L, h, n):
    """3D: the history ``h`` with each tangent-plane column of the law of row L turned
    onto the plane normal to the current normal n, its magnitude kept
    (the contact plane turns between steps; LIGGGHTS and Yade do the same)."""
    code = ti.cast(lawp[L, COL_CODE], ti.i32)
    for c in ti.static(range(len(laws))):
        if code == c:
            for first in ti.static(tangential_firsts(laws[c])):
                h = _turned(h, first, n)
    return h


@ti.func
def law_force_3d(laws: ti.template(), lawp: ti.template(), L, u, vn, vt, meff, reff, dt, h,
                 n):
    """:func:`law_force` in 3D, the history's tangent-plane columns first turned onto
    the plane normal to n (:func:`rotate_tangential`), in one dispatch."""
    code = ti.cast(lawp[L, COL_CODE], ti.i32)
    fn_el = 0.0
    fn = 0.0
    fs_tot = vt * 0.0
    kn = 0.0
    cn = 0.0
    diss = 0.0
    hout = h
    for c in ti.static(range(len(laws))):
        if code == c:
            hc = h
            for first in ti.static(tangential_firsts(laws[c])):
                hc = _turned(hc, first, n)
            q = _params(laws, c, lawp, L)
            fn_el, fn, fs_tot, kn, cn, diss, hout = ti.static(laws[c].force)(
                q, u, vn, vt, meff, reff, dt, hc)
    return fn_el, fn, fs_tot, kn, cn, diss, hout
