"""Rolling resistance of Jiang, Yu & Harris (2005).

One parameter delta sets the contact width B = delta * r_bar (Eq. 24), with the
common radius r_bar = 2 r_i r_j/(r_i + r_j) (Eq. 9b; 2 r_i against a wall,
Eq. 11b). Rolling stiffness K_m = K_n B²/12 (Eq. 29), rolling damping
mu_m = mu_n B²/12 (Eq. 49c). The relative rotation increment is
Δθ_r = (ω_i − ω_j) Δt (Eq. 13); the couple is incremental, M <- M − K_m Δθ_r,
and acts on i as +M and on j as −M (Eq. 52b).

- Model 1 (elastic–perfectly plastic, Eq. 35): |M| <= M0 = F_n B/6.
- Model 2 (elastic–brittle, Eq. 36 as written): M = −K_m θ_r while
  |θ_r| <= θ_r0 = 2 F_n/(K_n B) and M = 0 while |θ_r| > θ_r0, θ_r the relative
  rotation since the contact's rolling model was switched on (θ_r = 0 <-> M = 0), so
  the couple comes back when the rotation returns below θ_r0. With
  ``permanent_break=True`` the couple stays zero for that contact once it has dropped
  (a crushed contact width; an earlier reading of Eq. 36).

θ_r and the couple are held at zero while a contact's rolling resistance is off (δ = 0
or no model, as during a specimen's preparation), so θ_r counts from the moment the
model is switched on. Energy: a plastic or brittle change books the mean couple times
the "plastic" rotation (M_trial − M)/K_m as dissipation, so a Model 2 drop books the
spring's M²/(2 K_m) and a Model 2 return books it back (negative), and the account
stays closed.
"""
import taichi as ti

from tdem.core.errors import InputError

from .validate import non_negative

# the law table's columns of rolling resistance (physics.contact_law); the model column
# holds 1, 2 (Eq. 36) or MODEL2_PERMANENT (Model 2 with a permanent break)
COL_ROLL_DELTA, COL_ROLL_MODEL, COL_ROLL_DAMP = 1, 2, 3
MODEL2_PERMANENT = 3


class RollingResistance:
    """Rolling resistance at a contact (attach to a contact law's ``rolling``)."""

    def __init__(self, delta=0.4, model=1, damping=True, permanent_break=False):
        self.delta = non_negative("delta", delta)
        if model not in (1, 2):
            raise InputError(f"model must be 1 or 2, got {model!r}")
        self.model = int(model)
        self.damping = bool(damping)
        if permanent_break not in (True, False):
            raise InputError(f"permanent_break must be True or False, got {permanent_break!r}")
        if permanent_break and self.model != 2:
            raise InputError(f"permanent_break applies to model 2 only, got model={model!r}")
        self.permanent_break = bool(permanent_break)

    def column(self):
        """The model column of the law table."""
        return float(MODEL2_PERMANENT if self.permanent_break else self.model)

    def to_dict(self):
        return {"delta": self.delta, "model": self.model, "damping": self.damping,
                "permanent_break": self.permanent_break}

    def __repr__(self):
        extra = ", permanent_break=True" if self.permanent_break else ""
        return (f"RollingResistance(delta={self.delta}, model={self.model}, "
                f"damping={self.damping}{extra})")


@ti.func
def rolling_couple(lawp: ti.template(), L, fn_el, kn, cn, rbar, dw, dt, m_old, th_old, broken):
    """Rolling couple of one contact.

    dw = ω_i − ω_j; fn_el the elastic normal force; kn its (tangent) stiffness;
    cn the normal dashpot. Returns (spring couple, total couple on i, accumulated θ_r,
    broken flag, dissipated energy).
    """
    delta = lawp[L, COL_ROLL_DELTA]
    model = ti.cast(lawp[L, COL_ROLL_MODEL], ti.i32)
    th = 0.0
    m = 0.0
    m_tot = 0.0
    brk = 0.0
    diss = 0.0
    if model > 0 and delta > 0.0 and kn > 0.0:
        th = th_old + dw * dt
        brk = broken
        b = delta * rbar
        km = kn * b * b / 12.0
        m_trial = m_old - km * dw * dt
        m = m_trial
        capped = False
        if model == 1:
            m0 = ti.max(fn_el, 0.0) * b / 6.0
            if ti.abs(m) > m0:
                m = ti.math.sign(m) * m0
                capped = True
        else:
            th0 = 2.0 * ti.max(fn_el, 0.0) / (kn * b)
            if ti.abs(th) > th0 or (model == MODEL2_PERMANENT and brk > 0.5):
                brk = 1.0
                m = 0.0
            else:
                brk = 0.0
                m = -km * th
        # plastic or brittle change: mean couple times the plastic rotation
        # (M_trial − M)/K_m (module docstring); zero on the elastic branch
        diss += 0.5 * (m_old + m) * (m_trial - m) / km
        m_tot = m
        if lawp[L, COL_ROLL_DAMP] > 0.5 and brk < 0.5 and not capped:
            mu_m = cn * b * b / 12.0
            m_tot -= mu_m * dw
            diss += mu_m * dw * dw * dt
    return m, m_tot, th, brk, diss


@ti.func
def rolling_energy(lawp: ti.template(), L, kn, moment, rbar):
    """Energy stored in the rolling spring, M²/(2 K_m)."""
    e = 0.0
    delta = lawp[L, COL_ROLL_DELTA]
    if delta > 0.0 and kn > 0.0:
        b = delta * rbar
        km = kn * b * b / 12.0
        e = 0.5 * moment * moment / km
    return e


@ti.func
def rolling_couple_3d(lawp: ti.template(), L, fn_el, kn, cn, rbar, dw, n, dt, m_old, th_old,
                      broken):
    """3D: the rolling couple of one contact, the vector form of Jiang's models (as the
    EPSD model of LIGGGHTS and Yade's rolling stiffness): the relative rolling rotation
    is the tangent-plane part of (ω_i − ω_j) Δt (twisting about n is free), the spring
    couple M (a tangent-plane vector, turned onto the current plane with its magnitude
    kept, like the shear spring) takes the increment −K_m Δθ_r, Model 1 caps |M| at
    F_n B/6, Model 2 is −K_m θ_r while |θ_r| <= 2 F_n/(K_n B) and zero above (or zero
    for good, with a permanent break), and the rolling dashpot μ_m (module docstring)
    acts on the rolling rate while the spring is neither capped nor broken.
    dw = ω_i − ω_j, n the contact normal. Returns (spring couple, total couple on i, accumulated θ_r, broken flag, dissipated energy)."""
    delta = lawp[L, COL_ROLL_DELTA]
    model = ti.cast(lawp[L, COL_ROLL_MODEL], ti.i32)
    wr = dw - dw.dot(n) * n
    m = m_old * 0.0
    th = th_old * 0.0
    m_tot = m_old * 0.0
    brk = 0.0
    diss = 0.0
    if model > 0 and delta > 0.0 and kn > 0.0:
        m_prev = _onto_plane(m_old, n)
        th = _onto_plane(th_old, n) + wr * dt
        brk = broken
        b = delta * rbar
        km = kn * b * b / 12.0
        m_trial = m_prev - km * wr * dt
        m = m_trial
        capped = False
        if model == 1:
            m0 = ti.max(fn_el, 0.0) * b / 6.0
            mag = m.norm()
            if mag > m0:
                m = m * (m0 / mag)
                capped = True
        else:
            th0 = 2.0 * ti.max(fn_el, 0.0) / (kn * b)
            if th.norm() > th0 or (model == MODEL2_PERMANENT and brk > 0.5):
                brk = 1.0
                m = m * 0.0
            else:
                brk = 0.0
                m = -km * th
        # plastic or brittle change: mean couple times (M_trial − M)/K_m
        diss += (0.5 * (m_prev + m)).dot(m_trial - m) / km
        m_tot = m
        if lawp[L, COL_ROLL_DAMP] > 0.5 and brk < 0.5 and not capped:
            mu_m = cn * b * b / 12.0
            m_tot -= mu_m * wr
            diss += mu_m * wr.dot(wr) * dt
    return m, m_tot, th, brk, diss


@ti.func
def _onto_plane(v, n):
    """v turned onto the plane normal to n, its magnitude kept."""
    out = v
    m2 = v.dot(v)
    if m2 > 0.0:
        p = v - v.dot(n) * n
        p2 = p.dot(p)
        if p2 > 0.0:
            out = p * ti.sqrt(m2 / p2)
        else:
            out = p
    return out


@ti.func
def rolling_energy_3d(lawp: ti.template(), L, kn, moment, rbar):
    """Energy stored in the 3D rolling spring, |M|²/(2 K_m)."""
    e = 0.0
    delta = lawp[L, COL_ROLL_DELTA]
    if delta > 0.0 and kn > 0.0:
        b = delta * rbar
        km = kn * b * b / 12.0
        e = 0.5 * moment.dot(moment) / km
    return e
