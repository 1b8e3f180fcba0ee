"""The Danish straits: a real coastline shipped with terramesh for the demo.

Natural Earth 1:50m land (public domain) clipped to 9.6..13.2 E,
54.4..56.6 N: the Kattegat, the Belts and the Øresund, with ten islands.
"""

import json
from importlib import resources

import numpy as np
import shapely

from ..coastal.boundaries import make_boundaries
from ..generation.distmesh import generate_mesh
from ..geometry.polygon import Polygon

__all__ = ["danish_straits_land", "danish_straits_mesh"]

_EARTH_RADIUS_KM = 6371.0


def danish_straits_land():
    """Land polygons of the example and their box.

    Returns
    -------
    land : shapely.MultiPolygon
        Longitude, latitude in degrees (WGS84).
    bbox : tuple of float
        ``(lon_min, lat_min, lon_max, lat_max)``.
    """
    text = resources.files(__package__).joinpath("data/danish_straits_land.geojson").read_text()
    collection = json.loads(text)
    land = shapely.union_all([shapely.from_geojson(json.dumps(f["geometry"])) for f in collection["features"]])
    return shapely.make_valid(land), tuple(collection["bbox"])


def danish_straits_mesh(*, min_edge_km=1.5, max_edge_km=8.0, grade=0.25, seed=0):
    """Mesh the water of the Danish straits, fine at the coast, coarse offshore.

    The edge length grows linearly with distance to the coast,
    ``min_edge_km + grade * distance``, up to ``max_edge_km``. Meshing
    happens in kilometres on an equirectangular projection about the box
    centre (scale error under 3 % across the box), so that cells are
    isotropic on the ground; the result is in degrees.

    Parameters
    ----------
    min_edge_km, max_edge_km : float
        Smallest and largest edge length, km.
    grade : float
        Growth of the edge length per unit distance from the coast.
    seed : int
        Seed of the mesh generator.

    Returns
    -------
    Mesh
        Points in longitude, latitude (degrees); ``boundaries`` for ADCIRC
        (:func:`~terramesh.coastal.make_boundaries`): open ocean on the box's
        edge (the Kattegat and the Baltic), the coasts mainland and islands.

    Examples
    --------
    >>> mesh = danish_straits_mesh(min_edge_km=6, max_edge_km=12)
    >>> mesh.points.min(axis=0).round(6).tolist(), mesh.points.max(axis=0).round(6).tolist()
    ([9.6, 54.4], [13.2, 56.6])
    """
    land, (lon_min, lat_min, lon_max, lat_max) = danish_straits_land()
    center = np.array([0.5 * (lon_min + lon_max), 0.5 * (lat_min + lat_max)])
    km_per_degree = np.radians(1.0) * _EARTH_RADIUS_KM * np.array([np.cos(np.radians(center[1])), 1.0])

    def to_km(lonlat):
        return (np.asarray(lonlat) - center) * km_per_degree

    water = shapely.difference(shapely.box(lon_min, lat_min, lon_max, lat_max), land)
    water_km = shapely.transform(water, to_km)
    coast_km = shapely.transform(land, to_km)
    domain = Polygon.from_shapely(water_km)
    coast = Polygon.from_shapely(coast_km)

    def edge_length(points):
        return np.minimum(min_edge_km + grade * np.abs(coast.distance(points)), max_edge_km)

    mesh = generate_mesh(domain, edge_length, h0=min_edge_km, seed=seed)
    mesh.points = mesh.points / km_per_degree + center
    mesh.title = "Danish straits, terramesh demo (Natural Earth 1:50m coastline)"
    mesh.crs = "EPSG:4326"
    # no DEM here: the box's edge is the open sea
    return make_boundaries(mesh, bbox=(lon_min, lon_max, lat_min, lat_max), open_by="bbox")
