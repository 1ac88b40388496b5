"""A test for NaN and infinity inside kernels that holds under fast math.

Taichi compiles kernels with ``fast_math=True`` by default, which lets the compiler
assume that no float is NaN or infinite: ``x != x`` and ``ti.math.isnan(x)`` are then
folded to False. The test here looks at the bit pattern instead: a float is NaN or
infinite exactly when its exponent bits are all ones. Float32 values are widened to
float64 first (NaN stays NaN, infinity stays infinity).
"""
import taichi as ti

_EXP_MASK = 0x7FF0000000000000


@ti.func
def non_finite(x):
    """1 if the scalar ``x`` is NaN or ±infinity, else 0."""
    bits = ti.bit_cast(ti.cast(x, ti.f64), ti.u64)
    return ti.cast((bits & ti.u64(_EXP_MASK)) == ti.u64(_EXP_MASK), ti.i32)


@ti.func
def any_non_finite(v):
    """1 if any component of the vector ``v`` is NaN or ±infinity, else 0."""
    bad = 0
    for k in ti.static(range(v.n)):
        bad |= non_finite(v[k])
    return bad
