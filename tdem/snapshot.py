"""Device-side copy of the dynamic state (the restore point of a run segment).

One kernel, one loop over particles, so that taking a snapshot costs one launch
whatever the size of the system.
"""
import taichi as ti

from .launch import cached

# order of the arrays passed to :func:`copy_state` (sources, then destinations)
PER_PARTICLE = ("pos", "vel", "omega", "force", "torque", "xref", "eacc", "estate", "ncnt",
                "rcnt")
PER_SLOT = ("nbr", "hist", "cn", "cf", "cs", "rev")
PER_WALL_SLOT = ("wid", "whist", "wcn", "wcf", "wcs")
OTHER = ("wall", "wforce", "flags")
ORDER = PER_PARTICLE + PER_SLOT + PER_WALL_SLOT + OTHER


@cached
@ti.kernel
def copy_state(a0: ti.types.ndarray(), a1: ti.types.ndarray(), a2: ti.types.ndarray(),
               a3: ti.types.ndarray(), a4: ti.types.ndarray(), a5: ti.types.ndarray(),
               a6: ti.types.ndarray(), a7: ti.types.ndarray(), a8: ti.types.ndarray(),
               a9: ti.types.ndarray(), s0: ti.types.ndarray(), s1: ti.types.ndarray(), s2: ti.types.ndarray(),
               s3: ti.types.ndarray(), s4: ti.types.ndarray(), s5: ti.types.ndarray(),
               w0: ti.types.ndarray(), w1: ti.types.ndarray(), w2: ti.types.ndarray(),
               w3: ti.types.ndarray(), w4: ti.types.ndarray(),
               o0: ti.types.ndarray(), o1: ti.types.ndarray(), o2: ti.types.ndarray(),
               b0: ti.types.ndarray(), b1: ti.types.ndarray(), b2: ti.types.ndarray(),
               b3: ti.types.ndarray(), b4: ti.types.ndarray(), b5: ti.types.ndarray(),
               b6: ti.types.ndarray(), b7: ti.types.ndarray(), b8: ti.types.ndarray(),
               b9: ti.types.ndarray(), t0: ti.types.ndarray(), t1: ti.types.ndarray(), t2: ti.types.ndarray(),
               t3: ti.types.ndarray(), t4: ti.types.ndarray(), t5: ti.types.ndarray(),
               v0: ti.types.ndarray(), v1: ti.types.ndarray(), v2: ti.types.ndarray(),
               v3: ti.types.ndarray(), v4: ti.types.ndarray(),
               p0: ti.types.ndarray(), p1: ti.types.ndarray(), p2: ti.types.ndarray(),
               serial: ti.template()):
    """Copy (a*, s*, w*, o*) into (b*, t*, v*, p*), arrays in the order of ``ORDER``."""
    ti.loop_config(serialize=serial)
    for i in range(a0.shape[0]):
        b0[i] = a0[i]
        b1[i] = a1[i]
        b2[i] = a2[i]
        b3[i] = a3[i]
        b4[i] = a4[i]
        b5[i] = a5[i]
        b6[i] = a6[i]
        b7[i] = a7[i]
        b8[i] = a8[i]
        b9[i] = a9[i]
        for k in range(s0.shape[1]):
            t0[i, k] = s0[i, k]
            t1[i, k] = s1[i, k]
            t2[i, k] = s2[i, k]
            t3[i, k] = s3[i, k]
            t4[i, k] = s4[i, k]
            t5[i, k] = s5[i, k]
        for k in range(w0.shape[1]):
            v0[i, k] = w0[i, k]
            v1[i, k] = w1[i, k]
            v2[i, k] = w2[i, k]
            v3[i, k] = w3[i, k]
            v4[i, k] = w4[i, k]
    ti.loop_config(serialize=True)
    for w in range(o0.shape[0]):
        for c in range(o0.shape[1]):
            p0[w, c] = o0[w, c]
        p1[w] = o1[w]
    ti.loop_config(serialize=True)
    for f in range(o2.shape[0]):
        p2[f] = o2[f]
