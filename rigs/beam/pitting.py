"""Fatigue pitting of the pinion flanks: a discrete pit field per tooth and its slice-wise
loaded contact.

Pits nucleate along the profile with a hazard that grows with the Hertzian pressure of the
quasi-static load sharing at the pitting test load (power 8, the usual contact-fatigue
exponent range) and is higher below the pitch line, where the pinion flank sees negative
sliding. Each gearbox has its own fixed, ordered pit population per tooth (40 % of new pits
grow next to an existing one, so pits coalesce into clusters); a damage level is reached by
adding pits in order until the pitted fraction of the active flank hits the tooth's target,
so a later stage always contains the pits of an earlier one. Per-tooth targets scatter
log-normally around the mean.

The face width is cut into slices. On a contact line a slice carries load in proportion to
its unpitted part; slices are coupled through the tooth body (an exponential influence
kernel over a load-spreading length), so a pit both removes contact width and concentrates
the load on the remaining slices. The solution gives per tooth and path position the loaded
width fraction w and the body-compliance factor phi >= 1 used by the dynamic contact law.
"""
from __future__ import annotations

import numpy as np

N_FACE = 64            # raster columns across the face width
MAX_PITS = 600
SPREAD_LENGTH = 5.0e-3  # m, load-spreading length of the tooth body across the face
RIDGE_FLATTENING = 2.5e-6  # m, sinking of a contact line carrying twice its nominal line load


def pit_population(rng: np.random.Generator, hazard: np.ndarray, u: np.ndarray, width: float,
                   n_teeth: int) -> list[np.ndarray]:
    """Ordered pits per tooth: rows (u centre, z centre, half-length u, half-width z, depth)."""
    cdf = np.cumsum(hazard)
    cdf /= cdf[-1]
    pops = []
    for _ in range(n_teeth):
        rows = np.zeros((MAX_PITS, 5))
        for i in range(MAX_PITS):
            if i > 0 and rng.random() < 0.4:
                j = rng.integers(0, i)
                uc = rows[j, 0] + rng.normal(0, 0.5e-3)
                zc = rows[j, 1] + rng.normal(0, 0.7e-3)
            else:
                uc = np.interp(rng.random(), cdf, u)
                zc = rng.uniform(0, width)
            rows[i] = (np.clip(uc, u[0], u[-1]), np.clip(zc, 0, width),
                       0.30e-3 * rng.lognormal(0, 0.45), 0.45e-3 * rng.lognormal(0, 0.45),
                       rng.uniform(10e-6, 40e-6))
        pops.append(rows)
    return pops


def pit_coverage(pops, targets, u: np.ndarray, width: float):
    """Raster of pit depth (n_teeth, n_u, N_FACE) [m] reaching each tooth's pitted fraction."""
    z = (np.arange(N_FACE) + 0.5) * width / N_FACE
    depth = np.zeros((len(pops), u.size, N_FACE))
    reached = np.zeros(len(pops))
    for k, (rows, target) in enumerate(zip(pops, targets)):
        if target <= 0:
            continue
        covered = 0
        total = u.size * N_FACE
        for uc, zc, au, az, dp in rows:
            i0, i1 = np.searchsorted(u, [uc - au, uc + au])
            j0, j1 = np.searchsorted(z, [zc - az, zc + az])
            if i1 <= i0 or j1 <= j0:
                continue
            uu = (u[i0:i1, None] - uc) / au
            zz = (z[None, j0:j1] - zc) / az
            inside = uu**2 + zz**2 <= 1.0
            win = depth[k, i0:i1, j0:j1]
            covered += np.count_nonzero(inside & (win == 0))
            np.maximum(win, np.where(inside, dp, 0.0), out=win)
            if covered >= target * total:
                break
        reached[k] = covered / total
    return depth, reached


def slice_contact(depth: np.ndarray, body: np.ndarray, hertz_lin: np.ndarray, width: float,
                  n_slices: int):
    """Loaded width fraction w, body factor phi and pit-bottom gap per (tooth, u).

    depth: (n_teeth, n_u, N_FACE) pit depths; body, hertz_lin: (n_u,) compliances of the
    pair [m/N] (body of both teeth; Hertzian approach linearised at the nominal load).
    """
    n_t, n_u, n_f = depth.shape
    per = n_f // n_slices
    pitted = (depth > 0).reshape(n_t, n_u, n_slices, per).mean(axis=3)
    active = 1.0 - pitted
    w = active.mean(axis=2)
    phi = np.ones((n_t, n_u))
    gap = np.zeros((n_t, n_u))
    z = (np.arange(n_slices) + 0.5) * width / n_slices
    kern = np.exp(-np.abs(z[:, None] - z[None, :]) / SPREAD_LENGTH)
    kern *= n_slices / kern.sum(axis=1).mean()
    lost = w < 0.03
    # a contact line entirely inside pits bears on the shallowest pit bottom
    gap[lost] = depth[lost].min(axis=-1) if lost.any() else 0.0
    w = np.where(lost, 1.0, w)
    # the ridges left between pits carry the concentrated load and flatten plastically:
    # the loaded line sinks by RIDGE_FLATTENING (1/w - 1), at most to the pit bottom
    count = np.count_nonzero(depth > 0, axis=-1)
    bottom = depth.sum(axis=-1) / np.maximum(count, 1)
    gap = np.where(lost, gap, np.minimum(RIDGE_FLATTENING * (1.0 / np.maximum(w, 0.03) - 1.0), bottom))
    need = (w < 0.999) & ~lost
    ti, ui = np.nonzero(need)
    if ti.size:
        frac = np.maximum(active[ti, ui], 1e-4)                     # (m, n_slices)
        cb = body[ui][:, None, None] * kern[None]
        loc = n_slices * hertz_lin[ui][:, None] / frac
        loc = np.where(frac < 0.02, 1e3 * loc, loc)
        mats = cb + np.einsum("mi,ij->mij", loc, np.eye(n_slices))
        f = np.linalg.solve(mats, np.ones((ti.size, n_slices, 1)))[..., 0]
        c_tot = 1.0 / f.sum(axis=1)
        # the same slice model without pits is the reference (phi = 1 on a sound flank)
        ref = body[:, None, None] * kern[None] + np.einsum(
            "mi,ij->mij", np.repeat(n_slices * hertz_lin[:, None], n_slices, axis=1), np.eye(n_slices))
        c_ref = 1.0 / np.linalg.solve(ref, np.ones((n_u, n_slices, 1)))[..., 0].sum(axis=1)
        body_eff = c_tot - hertz_lin[ui] / w[ti, ui]
        phi[ti, ui] = np.maximum(body_eff / (c_ref[ui] - hertz_lin[ui]), 1.0)
    return w, phi, gap
