"""Domain corners the cells covered over, put back on the mesh's boundary."""

import numpy as np
import pytest
import shapely

import terramesh as tm
from terramesh.mesh.topology import boundary_edges


@pytest.mark.parametrize(
    ("base_angle", "size"),
    [
        (52.5, 0.3),  # the review's case: two cells each 49 % inside the hole, mesh_problems silent
        (75.0, 0.15),  # a 30-degree tip: 47 %
        (80.0, 0.1),  # a 20-degree tip: 41 %
    ],
)
def test_a_sharp_corner_of_a_hole_stays_on_the_boundary(base_angle, size):
    half = np.tan(np.radians(90.0 - base_angle))
    hole = shapely.Polygon([(0, 0), (-3 * half, -3), (3 * half, -3)])
    body = shapely.box(-4, -5, 4, 2).difference(hole)
    domain = tm.geometry.Polygon.from_shapely(body)
    mesh = tm.generate_mesh(domain, size, seed=0)
    cells = shapely.polygons(mesh.points[mesh.cells])
    outside = shapely.area(shapely.difference(cells, body)) / shapely.area(cells)
    assert outside.max() < 1e-6
    on_boundary = np.unique(boundary_edges(mesh.cells))
    for corner in hole.exterior.coords[:3]:
        vertex = int(np.argmin(np.linalg.norm(mesh.points - corner, axis=1)))
        assert np.linalg.norm(mesh.points[vertex] - corner) < 1e-9 and vertex in on_boundary
    assert tm.cleanup.mesh_problems(mesh, domain) == []
