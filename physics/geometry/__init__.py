"""Contact geometry: one function per pair of shapes.

A contact is geometry → law → accumulation (Yade's functors). The geometry of a
shape pair says whether two bodies touch and where: the overlap ``u``, the unit
normal ``n`` (from body i to body j), the branch lengths from the centres to the
contact point, and the relative velocity of j's contact point against i's. The
frame functions (:mod:`.frame`) split that velocity into its normal part and its
tangent-plane part ``vt`` — what every contact law takes (:mod:`physics.contact_law`)
— and turn the law's tangential force back into a vector.

Each pair is computed in two parts, so that a pair of neighbours that does not touch
costs only the first:

- ``overlap``: the gap test, from positions and sizes only;
- ``kinematics``: normal, branch lengths, relative velocity (touching pairs only).

Shape pairs today: disc–disc (:mod:`.disc_disc`) and disc–segment, a particle
against a rigid wall (:mod:`.disc_segment`). A new shape adds one file per pair it
meets and its state columns (:mod:`tdem.state`).

Conventions (physics notes §0–1): n points from i to j; in 2D t = n rotated +90°
and ω × r = ω(−r_y, r_x).
"""
from . import disc_disc, disc_segment, frame

__all__ = ["disc_disc", "disc_segment", "frame"]
