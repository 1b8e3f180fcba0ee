import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import terramesh as tm
from terramesh._kernels.lattice import _uniform
from terramesh.generation import seeding


def brute_force_seeds(domain, size, h0, bbox, salt, tolerance, top, band):
    """Every point of the finest lattice over the bbox, kept by the rule the nested search applies level by level."""
    extent = bbox[1] - bbox[0]
    j_max = int(np.floor(extent[1] / (h0 * np.sqrt(3) / 2)))
    i = np.arange(-(j_max // 2) - 1, int(np.floor(extent[0] / h0)) + 2)
    i, j = (a.ravel() for a in np.meshgrid(i, np.arange(j_max + 1), indexing="ij"))
    points = np.column_stack([bbox[0, 0] + h0 * (i + 0.5 * j), bbox[0, 1] + h0 * np.sqrt(3) / 2 * j])
    in_box = np.all((points >= bbox[0] - 1e-9 * extent) & (points <= bbox[1] + 1e-9 * extent), axis=1)
    points, i, j = points[in_box], i[in_box], j[in_box]
    distance, target = domain.distance(points), size(points)
    level = np.minimum(np.floor(np.log2(np.maximum(target / h0, 1.0))).astype(int), top)
    stride = 2**level
    on_lattice = (i % stride == 0) & (j % stride == 0)
    uniform = np.array([_uniform(a, b, salt) for a, b in zip(i, j, strict=True)])
    keep = on_lattice & (distance < tolerance) & (uniform < (stride * h0 / target) ** 2)
    if band is not None:
        keep &= distance > -band * target
    return points[keep]


@settings(max_examples=40, deadline=None)
@given(
    st.floats(0.5, 4.0),  # size at the centre, in h0
    st.floats(-0.4, 0.4),  # size gradient along x
    st.floats(-0.4, 0.4),  # and along y
    st.sampled_from([None, 1.0, 2.5]),
    st.integers(0, 2**31),
    st.integers(16, 400),  # lattice points of the top level: 1 to 5 levels
    st.booleans(),  # a polygon: its distances beyond a level's reach are skipped (distance_within)
)
def test_nested_search_finds_exactly_the_points_of_the_flat_rule(base, gx, gy, band, seed, coarsest, polygon):
    h0 = 0.02
    domain = tm.geometry.Disk((0.1, -0.05), 0.45)
    if polygon:  # the disk with a notch cut into it, as 60 segments
        angle = np.linspace(0, 2 * np.pi, 60, endpoint=False)
        radius = 0.45 - 0.25 * (np.abs(angle - np.pi) < 0.4)
        domain = tm.geometry.Polygon(np.column_stack([0.1 + radius * np.cos(angle), -0.05 + radius * np.sin(angle)]))
    bbox = np.array([[-0.4, -0.55], [0.6, 0.45]])

    def size(p):
        return h0 * base + np.abs(gx * (p[:, 0] - 0.1) + gy * (p[:, 1] + 0.05)) + h0  # >= h0, slope <= 0.57

    saved = seeding._COARSEST_POINTS
    seeding._COARSEST_POINTS = coarsest
    try:
        found, _ = seeding.seed_points(domain, size, h0, bbox, np.random.default_rng(seed), 1e-9, band=band)
    finally:
        seeding._COARSEST_POINTS = saved
    salt = np.uint64(np.random.default_rng(seed).integers(0, 2**63))
    extent = bbox[1] - bbox[0]
    j_max = int(np.floor(extent[1] / (h0 * np.sqrt(3) / 2)))
    fine = (int(np.floor(extent[0] / h0)) + 1 + j_max // 2 + 2) * (j_max + 1)
    top = max(0, int(np.ceil(0.5 * np.log2(fine / coarsest))))
    expected = brute_force_seeds(domain, size, h0, bbox, salt, 1e-9, top, band)
    assert set(map(tuple, found.tolist())) == set(map(tuple, expected.tolist()))
    assert len(found) == len(expected)


def test_uniform_numbers_are_uniform_and_depend_on_the_point_and_salt_only():
    i, j = np.meshgrid(np.arange(-150, 150), np.arange(300), indexing="ij")
    values = np.array([_uniform(a, b, np.uint64(7)) for a, b in zip(i.ravel(), j.ravel(), strict=True)])
    assert np.all((values >= 0) & (values < 1))
    counts, _ = np.histogram(values, bins=10, range=(0, 1))
    assert np.all(np.abs(counts - len(values) / 10) < 5 * np.sqrt(len(values) / 10))
    assert _uniform(3, 5, np.uint64(7)) == _uniform(3, 5, np.uint64(7)) != _uniform(3, 5, np.uint64(8))
