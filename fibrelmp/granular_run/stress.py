"""MUSEN's stress tensor of a sphere at a saved time point (``36``; its principal stresses are
``42``), from ``CCPUSimulator::PrepareAdditionalSavingData`` (e0ff360): for every solid bond and
every sphere-sphere contact of the last force evaluation, each of its two spheres adds (and a
sphere touching a wall adds unit(contact point - x) R with the wall's force on it)

    sigma[a][b] += r_c[a] * F[b] / V,   r_c = unit(x_other - x_self) * R,  V = pi (2 R)^3 / 6

with F the force on that sphere, R its radius and x the positions of the time point (cmusen
saves before the step's force evaluation, so the forces are the previous evaluation's: the
job's presave dumps, one step before each frame).  Bonds first, then contacts, as MUSEN sums
them; MUSEN takes unit(x_left - x_right) from the raw coordinates, also across a periodic
boundary, and so does this.
"""

from __future__ import annotations

import math

import numpy as np

from fibrelmp.numtext import fast as numtext_fast


def stress_tensors(rows: np.ndarray, position: np.ndarray, radius: np.ndarray,
                   pairs: list[tuple[np.ndarray, np.ndarray, np.ndarray]],
                   walls: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """(len(rows), 9) row-major tensors of the frame's spheres.  ``rows``/``position``: the
    frame's sphere rows and positions; ``radius``: every model row's radius; ``pairs``: per
    kind (bonds, then contacts), (row1, row2, force on row1) in the order MUSEN adds them;
    ``walls``: the sphere-wall contacts after them, (row, contact point, force on the
    sphere), each adding unit(point - x) R with its force.  Pairs and contacts with a sphere
    not in the frame add nothing."""
    count = len(radius)
    where = np.full(count, -1, np.int64)
    where[rows] = np.arange(len(rows))
    volume = math.pi * np.power(2 * np.asarray(radius, np.float64), 3.0) / 6
    arms, forces, vols, targets = [], [], [], []
    for r1, r2, force in pairs:
        k1, k2 = where[r1], where[r2]
        ok = (k1 >= 0) & (k2 >= 0)
        k1, k2, force = k1[ok], k2[ok], np.asarray(force, np.float64)[ok]
        conn = _normalized(position[k1] - position[k2])    # CVector3::Normalized
        # the pair's first sphere: (-1 * connVec) * R with F; the second: connVec * R with -F;
        # MUSEN adds them pair by pair, first sphere then second
        n = len(k1)
        c, f, v, k = np.empty((2 * n, 3)), np.empty((2 * n, 3)), np.empty(2 * n), np.empty(2 * n, np.int64)
        c[0::2], f[0::2], v[0::2], k[0::2] = (-1 * conn) * radius[r1[ok], None], force, volume[r1[ok]], k1
        c[1::2], f[1::2], v[1::2], k[1::2] = conn * radius[r2[ok], None], -1 * force, volume[r2[ok]], k2
        arms.append(c), forces.append(f), vols.append(v), targets.append(k)
    if walls is not None:
        r, point, force = walls
        k = where[r]
        ok = k >= 0
        r, k = r[ok], k[ok]
        arms.append(_normalized(point[ok] - position[k]) * radius[r, None])
        forces.append(np.asarray(force, np.float64)[ok]), vols.append(volume[r]), targets.append(k)
    sigma = np.zeros((len(rows), 9))
    if not targets:
        return sigma
    c, f, v, k = (np.concatenate(a) for a in (arms, forces, vols, targets))
    terms = (c[:, :, None] * f[:, None, :] / v[:, None, None]).reshape(-1, 9)
    # every sphere's terms added one after the other in the order given (bincount sums in
    # index order, as MUSEN's += do), each of the 9 components
    for col in range(9):
        sigma[:, col] = np.bincount(k, weights=terms[:, col], minlength=len(rows))
    return sigma


def _normalized(v: np.ndarray) -> np.ndarray:
    """CVector3::Normalized: v / sqrt(x*x + y*y + z*z), the zero vector for length 0."""
    length = np.sqrt(v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1] + v[:, 2] * v[:, 2])
    safe = np.where(length != 0, length, 1.0)
    return np.where(length[:, None] != 0, v / safe[:, None], 0.0)


def principal_stresses(s: np.ndarray) -> np.ndarray:
    """CMatrix3::GetPrincipalStresses of each row (9 values, row-major), with the C math
    library's functions (numtext's C helper, else Python's math module, ~3 µs a row) so that
    the digits are MUSEN's."""
    fast = numtext_fast.principal_stresses(s)
    if fast is not None:
        return fast
    out = np.zeros((len(s), 3))
    for i in np.flatnonzero(np.any(s != 0, axis=1)):
        m = s[i].tolist()
        a, b, c, d, e, f = m[0], m[4], m[8], m[1], m[2], m[5]
        i1 = a + b + c
        # MUSEN's pow(x, 2.) is x * x as GCC compiles it (math.pow differs in the last bit for
        # some x: cmusen's digits are x * x's)
        i2 = a * b + b * c + c * a - d * d - e * e - f * f
        i3 = a * b * c - a * (f * f) - b * (e * e) - c * (d * d) + 2 * d * e * f
        q = min((3 * i2 - i1 * i1) / 9.0, 0.0)
        r = (2 * math.pow(i1, 3.) - 9 * i1 * i2 + 27 * i3) / 54
        root = math.sqrt(math.pow(-q, 3.))
        ratio = r / root if root != 0 else (math.nan if r == 0 else math.copysign(math.inf, r))
        gg = min(max(ratio, -1.0) if ratio == ratio else -1.0, 1.0)     # fmax(nan, -1) = -1
        te = math.acos(gg)
        sq = 2 * math.sqrt(-q)
        out[i] = (sq * math.cos(te / 3) + i1 / 3., sq * math.cos((te + 2 * math.pi) / 3) + i1 / 3.,
                  sq * math.cos((te + 4 * math.pi) / 3) + i1 / 3.)
    return out
