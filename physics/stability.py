"""The stable time step of a dense packing of discs (leapfrog, linear springs).

Cundall & Strack's critical step 2·sqrt(m/k) (C&S p. 54) is that of one mass on one
spring. A disc in a dense packing has up to six contacts, each with a normal, a
shear and (with rolling resistance) a rolling spring, and its rotation couples
through the shear springs: the fastest mode of the packing is faster. For the
densest packing of equal discs (the hexagonal lattice, six contacts each, moment of
inertia m r²/2) the highest eigenfrequency ω_max of the lattice's dynamical matrix
is found over its Brillouin zone (:func:`hex_lambda`), and the leapfrog is stable
for Δt < 2/ω_max:

    Δt_stable = 2 / sqrt(λ k_n / m),   λ = ω_max² m / k_n,

λ = 6 with k_s = 0 (translation only), 24 with k_s = k_n (the mode in which all the
discs spin the same way, each shear spring stretched by both), 12 at k_s = k_n/2:
Δt_stable / (2 sqrt(m/k_n)) = 1/sqrt(λ) = 0.41, 0.20 and 0.29. PFC's per-particle
bound from the sum of a particle's contact stiffnesses is of the same kind; this
one is the exact value for the hexagonal lattice, not a bound from above.
"""
import functools

import numpy as np

# the six neighbours of a hexagonal lattice of discs of radius 1, mass 1, I = 1/2
_ANG = np.arange(6) * np.pi / 3.0
_N = np.stack([np.cos(_ANG), np.sin(_ANG)], axis=1)
_T = np.stack([-_N[:, 1], _N[:, 0]], axis=1)


@functools.lru_cache(maxsize=256)
def hex_lambda(ks_over_kn, kroll_over_kn_r2=0.0, grid=73):
    """λ = ω_max² m/k_n of the hexagonal lattice of equal discs (radius r, mass m,
    inertia m r²/2) with normal springs k_n, shear springs k_s and rolling springs
    K_m (on the relative rotation), for k_s/k_n and K_m/(k_n r²). The largest
    eigenvalue of the Bloch dynamical matrix over a grid of wave vectors spanning
    the Brillouin zone (the maximum lies at its centre or its corners, which the grid
    holds)."""
    ks, km = float(ks_over_kn), float(kroll_over_kn_r2)
    q = np.linspace(-np.pi, np.pi, grid)
    qx, qy = np.meshgrid(q, q, indexing="ij")
    qx, qy = qx.ravel(), qy.ravel()
    D = np.zeros((qx.size, 3, 3), complex)
    scale = np.sqrt(np.array([1.0, 1.0, 2.0]))        # M^(-1/2): m = 1, I = 1/2
    for n, t in zip(_N, _T):
        # neighbour at 2n: phase of its displacement relative to this disc's
        ph = np.exp(1j * 2.0 * (qx * n[0] + qy * n[1]))
        # d(stretch)/d(dofs) of this disc (i) and the neighbour (j): dofs (x, y, θ)
        for k, bi, bj in ((1.0, (-n[0], -n[1], 0.0), (n[0], n[1], 0.0)),
                          (ks, (-t[0], -t[1], -1.0), (t[0], t[1], -1.0)),
                          (km, (0.0, 0.0, 1.0), (0.0, 0.0, -1.0))):
            if k == 0.0:
                continue
            b = (np.asarray(bi)[None, :] + np.asarray(bj)[None, :] * ph[:, None]) * scale
            # each bond is shared by two discs: half of it per disc and neighbour
            D += 0.5 * k * np.conj(b)[:, :, None] * b[:, None, :]
    return float(np.linalg.eigvalsh(D).max())


def stable_dt(kn, ks, mass, kroll_over_kn_r2=0.0):
    """Δt_stable of a hexagonal packing of discs of this mass with springs kn, ks
    (numbers or numpy arrays of one value per particle; one ks/kn ratio per call)."""
    kn = np.asarray(kn, dtype=float)
    ratio = float(np.max(np.asarray(ks, dtype=float) / kn)) if np.size(kn) else 0.0
    lam = hex_lambda(round(ratio, 6), round(float(kroll_over_kn_r2), 6))
    return 2.0 / np.sqrt(lam * kn / np.asarray(mass, dtype=float))
