"""How much shorter than their size a DistMesh mesh's shortest edges come out: what sizes for a time step allow for.

An explicit solver's time step is set by each vertex's (or cell's) shortest
edge, and the force equilibrium leaves the shortest edges around a vertex
below the size asked there. Sizes made so that a time step ``dt`` is stable
(the coastal CFL limit, the seismic ``dt``) are therefore divided by these
measured ratios: the mesh then keeps the step its sizes were made for.
"""

EDGE_SHRINK = 0.6
"""Shortest edge over its target size in a 2-D DistMesh mesh; CFL sizes of ``dt`` are divided by it.

Seismic, measured on the meshes of six 2-D models (uniform, two layers
1500/3000 and 1500/4500 m/s, a linear gradient, a 5 x 7.5 km salt crop of
BP2004, two seeds): the shortest edge was 0.60-0.73 of its size, and with
sizes ``k v_max dt / Cr`` alone the mesh's stable step was 0.65-0.80 ``dt``.
With 0.6 every one of them came out at 1.19-1.34 ``dt``; with 0.65 and 0.7
some fell below ``dt`` (0.90, 0.84).

Coastal (``tm.coastal.build`` with ``dt=0``, four boxes of GSHHS and Natural
Earth coasts on ETOPO1): without it the meshes reached Courant numbers of
0.56-0.80 at the chosen step where the sizes held 0.5 (0.5 over 0.625-0.89);
with it 0.34-0.48, and the guide's §5.3 mesh (``dt = 5`` s) 0.44.
"""

EDGE_SHRINK_SEISMIC = 0.5
""":data:`EDGE_SHRINK` for a 2-D seismic model's box, whose flat top compresses the row beneath it.

A BP2004 crop (241 x 801 nodes at 25 m, the top 6 km, 3 Hz, hmin 40 m, grade
0.15, 1 km padding; seeds 0-2) meshed for dt 0.02 and 0.025 s allowed 0.965-0.976
and 0.917-0.957 ``dt`` with 0.6: edges of the row under the flat top, in the water,
at 0.53-0.59 of their size. With 0.55, 1.015-1.160 at 0.02-0.025 s; with 0.5,
1.30-1.42 ``dt`` at 0.02-0.04 s (19.4k-19.7k vertices against 28.3k-28.5k at 0.02 s,
4.6k-4.7k against 6.9k at 0.04 s). The coastal CFL limit keeps 0.6: its meshes are
checked and mended after generation (:func:`~terramesh.coastal.enforce_timestep`).
"""

EDGE_SHRINK_3D = 0.4
"""The same for tetrahedral meshes, whose shortest edges come out shorter still.

With 0.6, meshes of a two-layer box (1500 over 3000 m/s, 4-6 Hz, dt 0.008-0.015 s)
had a stable step of 0.85-0.87 ``dt``, and with 0.45 of 0.91-0.96 at 3,700 vertices.
With 0.4 sixteen meshes (that box and a 1500-4500 m/s gradient, dt 0.006-0.015 s,
two seeds, 390-19,700 vertices) came out at 1.16-1.76 ``dt``. A few edges in
10**5 still came out under 0.4 of their size (the 3-D BP2004 example at
dt 0.035 s: 0.975 ``dt`` on one seed of six), so the 3-D generator moves the ends
of edges under 0.45 of their size apart where their cells allow it
(``SHORT_EDGE`` of :mod:`terramesh.generation.distmesh3d`): twelve meshes of that
example at 0.035 and 0.05 s came out at 1.13-1.39 ``dt``.
"""
