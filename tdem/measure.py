"""Measurements over a region, as PFC's measurement circles and spheres and Yade's
averages: the Love–Weber stress, porosity, coordination number and fabric tensor of
the particles whose centres lie in a box, a circle or a polygon (2D), or a box or a
sphere (3D).

For the particles p whose centres lie in the region (area, in 3D volume, V):

- porosity n = 1 − Σ_q |q ∩ region| / V over every particle q: the part of each
  disc or sphere inside the region, exact (:mod:`tdem.overlap_volume`: disc–box,
  disc–polygon, disc–circle, sphere–sphere closed forms; sphere–box by converged
  quadrature), the periodic images included. Superellipses, ellipsoids and
  polyhedra count whole where their centres lie (their intersection with the region
  is not worked out);
- stress σ = (1 − n)/(Σ_p V_p) Σ_p Σ_c sym((x_c − x_p) ⊗ f_c), V_p the area of p
  in 2D, its volume m_p/ρ_p in 3D, f_c the force of contact c on p at its contact
  point x_c (particle and wall contacts), tension-positive: the Love–Weber sum
  (Love 1927, Weber 1966) of the particles whose centres are inside, scaled by the
  solid they stand for, as PFC's measurement circles do. Dividing the sum by V
  instead would weigh the region by how many centres happen to fall in it. Over a
  region that holds a whole specimen in equilibrium it is the stress its boundary
  carries; the pairs inside a region count once from each side;
- coordination: the mean number of contacts (with particles and walls) of the
  particles in the region;
- fabric φ = (1/N_c) Σ_c n_c ⊗ n_c over the contacts of those particles (trace 1).

Contacts carried by PCMM elements are not contacts here (their stress is the
particles' ``stress``).
"""
import itertools
import math

import numpy as np

from . import overlap_volume as ov
from .errors import InputError
from .pack import _polygon_area


class Region:
    """2D: a box ((x0, y0), (x1, y1)), a circle ((cx, cy), r) or a polygon (K, 2);
    3D: a box ((x0, y0, z0), (x1, y1, z1)) or a sphere ((cx, cy, cz), r)."""

    def __init__(self, box=None, circle=None, polygon=None, sphere=None, dim=2):
        given = [k for k, v in (("box", box), ("circle", circle), ("polygon", polygon),
                                ("sphere", sphere)) if v is not None]
        kinds = ("box", "circle", "polygon") if dim == 2 else ("box", "sphere")
        if len(given) != 1:
            raise InputError(f"measure takes exactly one of "
                             f"{', '.join(k + '=' for k in kinds)} got {given or 'none'}")
        self.kind = given[0]
        self.dim = dim
        if self.kind not in kinds:
            raise InputError(f"{self.kind}: a {('2D', '3D')[dim == 2]} region; a {dim}D "
                             f"simulation measures over {' or '.join(kinds)}")
        try:
            if box is not None:
                lo, hi = np.asarray(box, dtype=float).reshape(2, dim)
                if not (np.all(np.isfinite([lo, hi])) and np.all(hi > lo)):
                    raise ValueError
                self.lo, self.hi = lo, hi
                self.area = float(np.prod(hi - lo))
            elif circle is not None or sphere is not None:
                c, r = circle if circle is not None else sphere
                self.c = np.asarray(c, dtype=float).reshape(dim)
                self.r = float(r)
                if not (np.all(np.isfinite(self.c)) and math.isfinite(self.r)
                        and self.r > 0):
                    raise ValueError
                self.area = (math.pi * self.r ** 2 if dim == 2
                             else 4.0 / 3.0 * math.pi * self.r ** 3)
            else:
                p = np.asarray(polygon, dtype=float)
                if p.ndim != 2 or p.shape[1] != 2 or len(p) < 3 or not np.isfinite(p).all():
                    raise ValueError
                self.area = abs(float(_polygon_area(p)))
                if self.area <= 0:
                    raise ValueError
                from matplotlib.path import Path
                self.path = Path(p)
        except (TypeError, ValueError):
            value = {"box": box, "circle": circle, "polygon": polygon,
                     "sphere": sphere}[self.kind]
            box_form = ("((x0, y0), (x1, y1)) with x1 > x0 and y1 > y0" if dim == 2 else
                        "((x0, y0, z0), (x1, y1, z1)) with x1 > x0, y1 > y0 and z1 > z0")
            raise InputError(f"{self.kind} must be "
                             + {"box": box_form,
                                "circle": "((cx, cy), r) with r > 0",
                                "sphere": "((cx, cy, cz), r) with r > 0",
                                "polygon": "(K, 2) vertices, K >= 3, of non-zero area"}
                             [self.kind] + f", got {value!r}") from None

    def contains(self, x):
        x = np.asarray(x, dtype=float).reshape(-1, self.dim)
        if self.kind == "box":
            return np.all((x >= self.lo) & (x <= self.hi), axis=1)
        if self.kind in ("circle", "sphere"):
            return np.sum((x - self.c) ** 2, axis=1) <= self.r ** 2
        return self.path.contains_points(x)


def _solid_inside(region, pos, radius, periodic):
    """Σ of the areas (3D: volumes) of the discs (spheres) inside the region, their
    images across the periodic axes included."""
    dim = region.dim
    if region.kind == "box":
        lo, hi = region.lo, region.hi
    elif region.kind == "polygon":
        v = region.path.vertices
        lo, hi = v.min(axis=0), v.max(axis=0)
    else:
        lo, hi = region.c - region.r, region.c + region.r
    spans = [(0.0,)] * dim
    for k, span in enumerate(list(periodic)[:dim]):
        if span is not None:
            length = span[1] - span[0]
            spans[k] = (0.0, -length, length)
    total = 0.0
    for shift in itertools.product(*spans):
        x = pos + np.asarray(shift)
        near = np.all((x + radius[:, None] > lo) & (x - radius[:, None] < hi), axis=1)
        if not near.any():
            continue
        x, r = x[near], radius[near]
        if region.kind == "box":
            part = (ov.disc_box_area(x, r, lo, hi) if dim == 2
                    else ov.sphere_box_volume(x, r, lo, hi))
        elif region.kind == "polygon":
            part = ov.disc_polygon_area(x, r, region.path.vertices)
        elif dim == 2:
            part = ov.disc_disc_area(x, r, region.c, region.r)
        else:
            part = ov.sphere_sphere_volume(x, r, region.c, region.r)
        total += float(np.sum(part))
    return total


def measure(sim, box=None, circle=None, polygon=None, sphere=None):
    """The measurements of the module docstring for ``sim`` now: a dict with stress
    (d, d) Pa (N/m² per metre of thickness in 2D), porosity, coordination, fabric
    (d, d), particles (how many), contacts (how many counted), area (the region's
    area, in 3D its volume; also as ``volume`` in 3D)."""
    dim = sim.dim
    region = Region(box, circle, polygon, sphere, dim)
    p = sim.particles.numpy() if sim.n_particles else None
    if p is None:
        raise InputError("measure needs particles: add some first")
    inside = region.contains(p["position"])
    c = sim.contacts.numpy()
    i, j = c["pairs"][:, 0], c["pairs"][:, 1]
    n = c["direction"]
    if dim == 2:
        t = np.stack([-n[:, 1], n[:, 0]], axis=1)
        f = -c["normal"][:, None] * n + c["shear"][:, None] * t      # on the first particle
    else:
        f = -c["normal_force"][:, None] * n + c["shear_force"]
    # each contact seen from each of its particles in the region: (owner, force, normal)
    sides = []
    own = inside[i]
    sides.append((i[own], f[own], c["point"][own]))
    part = (j >= 0)
    other = np.zeros(len(j), bool)
    other[part] = inside[j[part]]
    sides.append((j[other], -f[other], c["point"][other]))
    owner = np.concatenate([s[0] for s in sides])
    force = np.concatenate([s[1] for s in sides])
    point = np.concatenate([s[2] for s in sides])
    normal = np.concatenate([n[own], n[other]])
    arm = point - p["position"][owner]
    if any(q is not None for q in getattr(sim, "_periodic", ())):
        arm = sim._image(arm)       # the contact point seen from the owner's side
    s = np.einsum("ca,cb->ab", arm, force)
    npart = int(inside.sum())
    ncont = len(owner)
    fabric = (np.einsum("ca,cb->ab", normal, normal) / ncont) if ncont else np.zeros((dim, dim))
    rows = np.concatenate(sim._host["shape"]) if sim._has_shapes else None
    if dim == 2:
        size = math.pi * p["radius"] ** 2
        shaped = rows[:, 2] > 0 if rows is not None else np.zeros(len(size), bool)
        size = np.where(shaped, rows[:, 3], size) if rows is not None else size
    else:
        size = p["mass"] / np.concatenate(sim._host["density"])   # spheres, ellipsoids, polyhedra
        shaped = rows[:, 3] != 0 if rows is not None else np.zeros(len(size), bool)
    solid = float(np.sum(size[inside & shaped]))
    round_ = ~shaped
    solid += _solid_inside(region, p["position"][round_], p["radius"][round_],
                           getattr(sim, "_periodic", ()))
    porosity = 1.0 - solid / region.area
    held = float(np.sum(size[inside]))
    scale = (1.0 - porosity) / held if held > 0.0 else 0.0
    stress = 0.5 * (s + s.T) * scale
    out = {"stress": stress, "porosity": porosity,
           "coordination": ncont / npart if npart else 0.0, "fabric": fabric,
           "particles": npart, "contacts": ncont, "area": region.area}
    if dim == 3:
        out["volume"] = region.area
    return out
