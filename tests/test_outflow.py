"""The SPH pressure-outflow boundary (numpy): total force -p A n to 1e-12, linear weights,
the bounding box + search distance + 3 % projection margin, and the two flux estimates."""

from __future__ import annotations

import numpy as np

from fibrelmp.mesh.outflow import MARGIN, Opening, flux, near, share, triangles_of


def _square(size=2.0, z=0.0, tilt=None):
    """A square opening of two triangles in the plane z (outward +z), optionally rotated."""
    pts = np.array([[0, 0, z], [size, 0, z], [size, size, z], [0, size, z]], float)
    if tilt is not None:
        pts = pts @ tilt.T
    return Opening(triangles_of(pts, [("quad", np.array([[0, 1, 2, 3]]))]))


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_total_force_is_minus_p_a_n_every_cycle():
    rng = np.random.default_rng(11)
    for cycle in range(20):
        rot = _rotation(rng)
        opening = _square(size=1.5 + cycle * 0.1, tilt=rot)
        x = (rng.random((4000, 3)) * [2.0, 2.0, 0.6] - [0.2, 0.2, 0.4]) @ rot.T
        p = 1000.0 + 50.0 * np.sin(cycle)
        s = share(opening, x, 0.2, p)
        expected = -p * opening.area * opening.normal
        assert len(s.rows) > 100
        np.testing.assert_allclose(s.force.sum(axis=0), expected, rtol=1e-12, atol=1e-12 * abs(expected).max())
        assert abs(opening.area - (1.5 + cycle * 0.1) ** 2) < 1e-12


def test_half_the_search_distance_gets_half_the_weight():
    opening = _square()
    d = 0.4
    # on the plane, at d/2 behind it (the fluid's side), in front of it (has left), beyond d
    x = np.array([[1.0, 1.0, 0.0], [0.5, 0.5, -0.2], [1.5, 1.2, 0.2], [1.0, 1.0, -0.41], [1.2, 0.7, -0.4]])
    s = share(opening, x, d, 100.0)
    assert s.rows.tolist() == [0, 1, 4]
    np.testing.assert_allclose(s.weight, [1.0, 0.5, 0.0], rtol=1e-15, atol=1e-15)
    norms = np.linalg.norm(s.force, axis=1)
    np.testing.assert_allclose(norms[1] / norms[0], 0.5, rtol=1e-15)


def test_projection_margin_and_bounding_box():
    opening = _square(size=2.0)
    d = 0.5
    # projections just inside the 3 % margin beyond an edge (of a triangle 2 long: 0.06) and
    # just outside it; one particle inside the box but beside the opening
    inside = [2.0 + 0.9 * MARGIN * 2.0, 1.0, -0.1]
    outside = [2.0 + 1.1 * MARGIN * 2.0, 1.0, -0.1]
    far = [2.4, 1.0, -0.1]
    rows, _ = near(opening, np.array([inside, outside, far]), d)
    assert rows.tolist() == [0]


def test_flux_estimates():
    """Particles on a lattice over the opening flowing through it at speed u: both estimates
    give A u per unit time (one cycle of dt: A u dt)."""
    opening = _square(size=1.0)
    h = 0.02
    g = np.arange(0.0, 1.0 - h / 2, h) + h / 2             # 50 columns over the 1 x 1 opening
    z = np.arange(-0.3, 0.3, h) + h / 3
    x = np.array(np.meshgrid(g, g, z, indexing="ij")).reshape(3, -1).T
    u, dt = 0.5, 0.004
    v = np.tile([0.0, 0.0, u], (len(x), 1))
    crossing, velocity = flux(opening, x, x + v * dt, v, 0.1, h ** 3)
    assert abs(velocity - opening.area * u) < 1e-12
    # the particles that cross in one cycle are those within u dt behind the plane
    rows, _ = near(opening, x, 0.1)
    behind = -((x[rows] - [0, 0, 0]) @ opening.normal)
    assert abs(crossing - np.count_nonzero(behind < u * dt) * h ** 3) < 1e-15
    # lattice planes 0.02 apart move 0.002 per cycle: 1 in 10 cycles crosses; over 10 cycles
    # the crossing estimate averages A u dt
    total = 0.0
    for k in range(10):
        a, b = x + v * dt * k, x + v * dt * (k + 1)
        total += flux(opening, a, b, v, 0.1, h ** 3)[0]
    np.testing.assert_allclose(total / 10, opening.area * u * dt, rtol=0.05)
