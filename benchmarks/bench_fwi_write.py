"""Writing FWI meshes (``write_fwi_mesh``): the validity check, the boundary facets and the files; prints a table.

Usage: python benchmarks/bench_fwi_write.py [bricks] [squares] [--repeat N]
(default 50 and 633: a box of 50**3 bricks cut into 750,000 tetrahedra, 132,651
vertices, and a square of 633**2 squares cut into 801,378 triangles, 401,956
vertices; about a minute)

Structured meshes, valid and quick to make (a brick into six positive
tetrahedra sharing its diagonal, a square into two triangles), so the sizes are
exact and the meshes the same from run to run. Each step is timed ``--repeat``
times (default 3): the fastest and the slowest are shown, since the machine is
shared. ``check`` is what the writer refuses invalid meshes by
(``mesh_problems`` without overlaps and hanging nodes), ``facets`` the
boundary facets it writes (``boundary_sides``, a census of every facet), and
``msh``/``vtu`` whole writes of each format, the check included, without a
velocity model.
"""

import argparse
import itertools
import tempfile
import time
from pathlib import Path

import numpy as np

import terramesh as tm
from terramesh.cleanup import mesh_problems
from terramesh.io.fwi import boundary_sides, write_fwi_mesh


def brick_box(n):
    """The unit cube as ``n**3`` bricks of six positive tetrahedra each."""
    axis = np.linspace(0.0, 1.0, n + 1)
    points = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)
    step = np.array([(n + 1) ** 2, n + 1, 1])
    corner = np.stack(np.meshgrid(*[np.arange(n)] * 3, indexing="ij"), axis=-1).reshape(-1, 3) @ step
    cells = np.concatenate(
        [
            np.column_stack([corner, corner + step[a], corner + step[a] + step[b], corner + step.sum()])
            for a, b in itertools.permutations(range(3), 2)  # the first two steps of each path to the far corner
        ]
    )
    a, b, c, d = (points[cells[:, k]] for k in range(4))
    negative = np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a) < 0
    cells[negative, :2] = cells[negative, 1::-1]
    return tm.Mesh(points, cells)


def square(n):
    """The unit square as ``n**2`` squares of two counter-clockwise triangles each."""
    axis = np.linspace(0.0, 1.0, n + 1)
    points = np.stack(np.meshgrid(axis, axis, indexing="ij"), axis=-1).reshape(-1, 2)
    corner = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    cells = np.concatenate(
        [
            np.column_stack([corner, corner + n + 1, corner + n + 2]),
            np.column_stack([corner, corner + n + 2, corner + 1]),
        ]
    )
    return tm.Mesh(points, cells)


def spread(call, repeat):
    """Fastest and slowest of ``repeat`` runs of ``call()``, in seconds."""
    seconds = []
    for _ in range(repeat):
        started = time.perf_counter()
        call()
        seconds.append(time.perf_counter() - started)
    return min(seconds), max(seconds)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bricks", nargs="?", type=int, default=50)
    parser.add_argument("squares", nargs="?", type=int, default=633)
    parser.add_argument("--repeat", type=int, default=3)
    arguments = parser.parse_args(argv)
    meshes = {"3-D box": brick_box(arguments.bricks), "2-D square": square(arguments.squares)}
    print(f"{'mesh':>10} {'vertices':>9} {'cells':>9} {'step':>6} {'fastest s':>9} {'slowest s':>9}")
    with tempfile.TemporaryDirectory() as folder:
        for name, mesh in meshes.items():
            boundary_sides(mesh)  # compiling, not timed
            if mesh_problems(mesh, overlaps=False, hanging_nodes=False):
                raise RuntimeError(f"the {name} mesh is not valid")
            steps = {
                "check": lambda mesh=mesh: mesh_problems(mesh, overlaps=False, hanging_nodes=False),
                "facets": lambda mesh=mesh: boundary_sides(mesh),
                "msh": lambda mesh=mesh: write_fwi_mesh(Path(folder) / "mesh.msh", mesh),
                "vtu": lambda mesh=mesh: write_fwi_mesh(Path(folder) / "mesh.vtu", mesh),
            }
            for step, call in steps.items():
                fastest, slowest = spread(call, arguments.repeat)
                print(
                    f"{name:>10} {mesh.n_points:>9,} {mesh.n_cells:>9,} {step:>6} {fastest:>9.2f} {slowest:>9.2f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
