"""Geometry of a sphere against a rigid triangle (a face of a mesh wall, 3D).

The triangle point nearest the sphere's centre x_i (Ericson, *Real-Time Collision
Detection*, §5.1.5, by the Voronoi regions of the vertices, edges and face) names
the feature touched: the face, an edge or a vertex. With d the vector from x_i to
that point the sphere touches when |d| < R_i: overlap u = R_i − |d|, normal
n = d/|d| (from the sphere to the wall, the wall being "j", of infinite radius and
mass), contact point x_c = x_i + (R_i − u/2) n. This covers the face contact of
Miyata's Eqs. 50–59 and the edge and vertex contacts the seed leaves out. Where a
sphere touches several triangles of one mesh, the engine keeps the face contacts
and drops edge and vertex contacts of that mesh (those lie on a face's border: the
seam of a flat or convex surface), and keeps one of several edge or vertex contacts
at the same point (:func:`tdem.step.mesh_contacts`), so that a sphere crossing the
seams of a flat triangulated floor feels one plane.
"""
import taichi as ti

FACE, EDGE, VERTEX = 0, 1, 2


@ti.func
def closest_point(p, a, b, c):
    """(closest point of triangle abc to p, feature: FACE, EDGE or VERTEX)."""
    ab = b - a
    ac = c - a
    ap = p - a
    d1 = ab.dot(ap)
    d2 = ac.dot(ap)
    q = a
    feat = VERTEX
    done = False
    if d1 <= 0.0 and d2 <= 0.0:
        done = True
    bp = p - b
    d3 = ab.dot(bp)
    d4 = ac.dot(bp)
    if not done and d3 >= 0.0 and d4 <= d3:
        q = b
        done = True
    cp = p - c
    d5 = ab.dot(cp)
    d6 = ac.dot(cp)
    if not done and d6 >= 0.0 and d5 <= d6:
        q = c
        done = True
    vc = d1 * d4 - d3 * d2
    if not done and vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        q = a + d1 / (d1 - d3) * ab
        feat = EDGE
        done = True
    vb = d5 * d2 - d1 * d6
    if not done and vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        q = a + d2 / (d2 - d6) * ac
        feat = EDGE
        done = True
    va = d3 * d6 - d5 * d4
    if not done and va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        q = b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)
        feat = EDGE
        done = True
    if not done:
        den = 1.0 / (va + vb + vc)
        q = a + ab * (vb * den) + ac * (vc * den)
        feat = FACE
    return q, feat
