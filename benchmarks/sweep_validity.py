"""Validity sweep: random domains, sizes, seeds and strips; each run gives a valid mesh or a clear error.

Usage: python benchmarks/sweep_validity.py [2d|3d|coast|seismic|aniso] [runs] [first]   (default 2d 200 0)

2d: star polygons (with a hole or not), random-walk coasts, a rectangle less or
plus disks, slotted squares; sizes uniform, linear or growing with the distance
to the boundary (up to 20x); default or forced coarse levels; whole or 2-3
strips (`generate_mesh_parallel`). 3d: a box, ball or cylinder, or the union,
difference or intersection of two, default or forced coarse levels. coast: boxes of 1-8 degrees of the three
shorelines in ../shared/data/coast, sizes growing from h0 with the distance to
the coast; whole, `tm.coastal.build` (distance, feature size, and with the
ETOPO1 DEM wavelength, slope and a CFL time step, each or not), or 2-3 strips.
seismic: windows of the BP2004 section, decimated, sized by
`tm.seismic.size_function` (frequency, hmin, grade, padding, gradient
refinement drawn at random), whole or in 2 or 4 strips. aniso: the 2d domains
meshed by `tm.generate_anisotropic_mesh` for a metric 1-30 times finer across
than along, growing away from a random point and turning across the domain.

Run k draws everything from seed k, so a row can be run again alone. Outcomes:
"valid" (`mesh_problems` finds nothing), "invalid" (a mesh that breaks a rule:
a bug), "refused" (a terramesh error: thin parts, sizes larger than the domain,
a bbox all land; the first words are counted), "crash" (any other exception: a
bug), "poor" (3D: a valid mesh with a cell of radius ratio below 0.2, where the polish
lifts cells to 0.3: a lost point's cap looked like that; 2D: a cell of quality below 0.2),
"relaxed" (aniso: a valid mesh that needed rounder cells at the boundary than the metric
asks). Prints a table of the counts and every run that was not valid.
"""

import collections
import pathlib
import re
import sys
import time
import warnings

import numpy as np

import terramesh as tm
from terramesh.errors import TerrameshError
from terramesh.quality.tetra import radius_ratio

COAST = pathlib.Path(__file__).resolve().parents[2] / "shared" / "data" / "coast"
ETOPO1 = COAST.parent / "dem" / "ETOPO1_0.1.grd"
SEISMIC = COAST.parent / "seismic"
SHORELINES = ("GSHHS_l_L1.shp", "ne_50m_land.shp", "ne_10m_land.shp")
POOR = "poor"  # 3D: a valid mesh whose worst cell is below...
POOR_RADIUS_RATIO = 0.2  # ...this radius ratio, where the polish lifts cells to 0.3 (a lost point left 0.015)
POOR_QUALITY = 0.2  # 2D: the same for triangle quality, the jagged-coast property test's bar
RELAXED = "relaxed"  # aniso: a valid mesh with rounder cells at the boundary than the metric asks (relax_boundary)
REGIONS = ((-100, -50, 10, 60), (-10, 30, 35, 65), (100, 150, -45, 10), (-80, -60, -56, -20), (120, 150, 25, 45))


def random_walk_coast(rng, n):
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    radius = 1 + rng.uniform(0.2, 0.9) * np.cumsum(rng.normal(size=n)) / np.sqrt(n)
    radius = np.maximum(radius - np.linspace(0, 1, n) * (radius[-1] - radius[0]), 0.3)
    return tm.geometry.Polygon(np.column_stack([radius * np.cos(angle), radius * np.sin(angle)]))


def domain_2d(rng):
    kind = rng.integers(0, 4)
    if kind == 0:
        n = int(rng.integers(5, 40))
        angle = np.linspace(0, 2 * np.pi, n, endpoint=False) + rng.uniform(-0.4, 0.4, n) * 2 * np.pi / n
        radius = rng.uniform(0.4, 1.0, n)
        rings = [np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])]
        if rng.random() < 0.5:
            hole = np.linspace(0, 2 * np.pi, int(rng.integers(3, 12)), endpoint=False)[::-1]
            radius, centre = rng.uniform(0.05, 0.2), rng.uniform(-0.1, 0.1, 2)
            rings.append(radius * np.column_stack([np.cos(hole), np.sin(hole)]) + centre)
        return tm.geometry.Polygon(rings), f"star of {n}"
    if kind == 1:
        n = int(rng.integers(200, 3000))
        return random_walk_coast(rng, n), f"random walk of {n}"
    if kind == 2:
        plate = tm.geometry.Rectangle((-1, -0.6), (1, 0.6))
        a, b = (tm.geometry.Disk(tuple(rng.uniform(-0.8, 0.8, 2)), rng.uniform(0.1, 0.5)) for _ in range(2))
        return [plate - a, (plate - a) | b, (plate - a) - b][rng.integers(0, 3)], "plate and disks"
    width = rng.uniform(0.02, 0.2)
    return tm.geometry.Rectangle((-1, -1), (1, 1)) - tm.geometry.Rectangle((-0.5, -width / 2), (1.5, width / 2)), (
        f"slot {width:.3f} wide"
    )


def run_2d(rng):
    domain, name = domain_2d(rng)
    h = float(rng.uniform(0.015, 0.08))
    growth = float(rng.choice([0.0, rng.uniform(0, 3), rng.uniform(3, 20)]))
    direction = rng.normal(size=2)
    direction /= np.linalg.norm(direction)
    if rng.random() < 0.5:

        def size(p):
            return h * (1 + growth * (1.5 + p @ direction) / 3)
    else:

        def size(p):
            return h * (1 + growth * np.minimum(np.abs(domain.distance(p)), 1.0))

    options = {} if rng.random() < 0.4 else {"levels": int(rng.integers(0, 3))}
    parts, seed = int(rng.choice([1, 1, 1, 2, 3])), int(rng.integers(0, 1000))
    label = f"{name}, h {h:.3f} x{1 + growth:.1f}, {parts} part(s), {options or 'default levels'}, seed {seed}"

    def problems():
        mesh = tm.parallel.generate_mesh_parallel(domain, size, h0=h, parts=parts, seed=seed, **options)
        found = tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * h)
        worst = float(tm.quality.triangle_quality(mesh.points, mesh.cells).min())
        return found or ([f"{POOR}: worst quality {worst:.3f}"] if worst < POOR_QUALITY else [])

    return label, problems


def solid(rng):
    kind, centre = rng.integers(0, 3), tuple(rng.uniform(-0.5, 0.5, 3))
    if kind == 0:
        half = rng.uniform(0.3, 1.0, 3)
        return tm.geometry.Box(tuple(np.subtract(centre, half)), tuple(np.add(centre, half))), "box"
    if kind == 1:
        return tm.geometry.Ball(centre, float(rng.uniform(0.3, 1.0))), "ball"
    axis = tuple(np.eye(3)[rng.integers(0, 3)])
    return tm.geometry.Cylinder(centre, float(rng.uniform(0.2, 0.6)), float(rng.uniform(1.0, 2.5)), axis=axis), "cyl"


def run_3d(rng):
    (a, name_a), (b, name_b) = solid(rng), solid(rng)
    operation = int(rng.integers(0, 4))
    name = [name_a, f"{name_a} | {name_b}", f"{name_a} - {name_b}", f"{name_a} & {name_b}"][operation]
    h, growth = float(rng.uniform(0.08, 0.2)), float(rng.choice([0.0, rng.uniform(0.5, 3)]))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    seed = int(rng.integers(0, 100))
    options = {} if rng.random() < 0.4 else {"levels": int(rng.integers(0, 3))}  # drawn last: earlier runs as before
    label = f"{name}, h {h:.3f} x{1 + growth:.1f}, {options or 'default levels'}, seed {seed}"

    def size(p):
        return h * (1 + growth * (2 + p @ direction) / 4)

    def problems():
        domain = [lambda: a, lambda: a | b, lambda: a - b, lambda: a & b][operation]()  # a & b apart: refused
        mesh = tm.generate_mesh(domain, size, h0=h, seed=seed, **options)
        found = tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * h)
        worst = float(radius_ratio(mesh.points, mesh.cells).min())
        return found or ([f"{POOR}: worst radius ratio {worst:.3f}"] if worst < POOR_RADIUS_RATIO else [])

    return label, problems


def run_coast(rng):
    shoreline = str(COAST / SHORELINES[rng.integers(0, len(SHORELINES))])
    region = REGIONS[rng.integers(0, len(REGIONS))]
    width = float(rng.uniform(1, 8))
    x0, y0 = rng.uniform(region[0], region[1] - width), rng.uniform(region[2], region[3] - 0.7 * width)
    bbox = (float(x0), float(x0 + width), float(y0), float(y0 + 0.7 * width))
    h0, grade = float(width / rng.uniform(40, 200)), float(rng.uniform(0.05, 0.3))
    parts, seed, build = int(rng.choice([1, 1, 2, 3])), int(rng.integers(0, 100)), rng.random() < 0.5
    label = f"{pathlib.Path(shoreline).name} {np.round(bbox, 2).tolist()}, h0 {h0:.4f} g {grade:.2f}, seed {seed}"

    # the guide's size functions, those of the DEM (ETOPO1) in half the runs
    options = {"fs": 3} if rng.random() < 0.5 else {"dis": grade}  # the guide takes one of the two
    options["g"] = float(rng.choice([0.15, 0.2, 0.35]))
    dem = str(ETOPO1) if rng.random() < 0.5 else None
    if dem:
        options.update({"wl": 30} if rng.random() < 0.5 else {})
        options.update({"slp": 20} if rng.random() < 0.5 else {})
        options.update({"dt": 0} if rng.random() < 0.5 else {})

    def built():
        sizes = {"min_el": h0 * 111e3, "max_el": 20 * h0 * 111e3, **options}
        mesh = tm.coastal.build(bbox, shoreline, dem, seed=seed, **sizes)
        return tm.cleanup.mesh_problems(mesh)

    def problems():
        water = tm.geometry.Polygon.from_shapely(tm.coastal.Shoreline.read(shoreline, bbox, 0.5 * h0 * 111e3).water)
        x, y = np.linspace(bbox[0], bbox[1], 201), np.linspace(bbox[2], bbox[3], 201)
        grid = np.stack(np.meshgrid(x, y, indexing="ij"), axis=-1).reshape(-1, 2)
        distance = np.abs(water.distance(grid)).reshape(201, 201)
        size = tm.sizing.SizeGrid((x, y), np.minimum(h0 + grade * distance, 20 * h0))
        mesh = tm.parallel.generate_mesh_parallel(water, size, h0=h0, parts=parts, seed=seed)
        return tm.cleanup.mesh_problems(mesh, water, boundary_tolerance=1e-3 * h0)

    if parts == 1 and build:
        return f"{label}, build {options}{' with ETOPO1' if dem else ''}", built
    return f"{label}, {parts} part(s)", problems


_BP2004 = []


def run_seismic(rng):
    if not _BP2004:
        _BP2004.append(tm.seismic.read_velocity(SEISMIC / "vel_z6.25m_x12.5m_exact.segy"))
    section = _BP2004[0]
    x, z = section.axes
    step = int(rng.choice([4, 8, 16]))
    i0 = int(rng.integers(0, len(x) // 2))
    i1 = int(min(len(x), i0 + rng.integers(len(x) // 8, len(x) // 2)))
    j1 = int(rng.integers(len(z) // 4, len(z)))
    model = tm.seismic.VelocityModel(section.values[i0:i1:step, :j1:step], (x[i0:i1:step], z[:j1:step]))
    options = {
        "frequency": float(rng.uniform(1, 5)),
        "hmin": float(rng.uniform(30, 150)),
        "grade": float(rng.uniform(0.1, 0.3)),
    }
    options.update({"pad": float(rng.uniform(500, 3000))} if rng.random() < 0.5 else {})
    options.update({"gradient_refinement": 1} if rng.random() < 0.3 else {})
    parts, seed = int(rng.choice([1, 1, 2, 4])), int(rng.integers(0, 100))
    width, depth = float(x[i1 - 1] - x[i0]), float(z[j1 - 1] - z[0])
    label = f"BP2004 {width / 1e3:.1f} x {depth / 1e3:.1f} km every {step}, {options}, {parts} part(s), seed {seed}"

    def problems():
        size = tm.seismic.size_function(model, **options)
        mesh = tm.parallel.generate_mesh_parallel(size.domain, size, parts=parts, seed=seed)
        return tm.cleanup.mesh_problems(mesh, size.domain, boundary_tolerance=1e-3 * options["hmin"])

    return label, problems


def run_anisotropic(rng):
    domain, name = domain_2d(rng)
    major, ratio = float(rng.uniform(0.04, 0.12)), float(rng.choice([rng.uniform(1, 10), rng.uniform(10, 30)]))
    turn, angle, centre = float(rng.uniform(0, 3)), float(rng.uniform(0, np.pi)), rng.uniform(-0.3, 0.3, 2)
    growth = float(rng.uniform(0, 2))

    def metric(p):  # sizes grow away from a point, the long axis turns across the domain
        along = major * (1 + growth * np.hypot(*(p - centre).T))
        return tm.sizing.metric_tensor(along, along / ratio, angle + turn * p[:, 0])

    seed = int(rng.integers(0, 1000))
    label = f"{name}, major {major:.3f} ratio {ratio:.1f} turning {turn:.1f} rad/unit, seed {seed}"

    def problems():
        mesh = tm.generate_anisotropic_mesh(domain, metric, seed=seed)
        # boundary vertices within 1e-3 of the isotropic start's smallest size (its h0), as the generator holds them
        found = tm.cleanup.mesh_problems(mesh, domain, boundary_tolerance=1e-3 * mesh.info["start"]["h0"])
        ratio = mesh.info["boundary_ratio"]
        return found or ([f"{RELAXED}: cells at most {ratio:g}:1 at the boundary"] if ratio is not None else [])

    return label, problems


def _noted(problem):
    """Whether a run's first problem is a note on a valid mesh (poor, relaxed), not a broken rule."""
    return problem.startswith((POOR, RELAXED))


def main(kind="2d", runs=200, first=0):
    run = {"2d": run_2d, "3d": run_3d, "coast": run_coast, "seismic": run_seismic, "aniso": run_anisotropic}[kind]
    outcomes, notes, started = collections.Counter(), [], time.perf_counter()
    for k in range(first, first + runs):
        label, compute = run(np.random.default_rng(k))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                problems = compute()
            outcome = "valid" if not problems else problems[0].split(":")[0] if _noted(problems[0]) else "invalid"
            if problems:
                notes.append(f"{k:5d} {outcome:8s} {label}: {problems[0]}")
        except TerrameshError as error:
            gist = re.sub(r"^strip \d+ of \d+ \([^)]*\): ", "", str(error))  # the same reasons in strips...
            gist = re.sub(r"\([^)]*\)", "(...)", gist)  # ...and boxes
            outcome = "refused: " + " ".join(gist.split()[:5])
            notes.append(f"{k:5d} refused  {label}: {str(error)[:160]}")
        except Exception as error:  # a bug: say where
            outcome = "crash"
            notes.append(f"{k:5d} CRASH    {label}: {type(error).__name__}: {str(error)[:160]}")
        outcomes["valid" if outcome == "valid" else outcome] += 1
    print(f"{kind}: runs {first}-{first + runs - 1}, {time.perf_counter() - started:.0f} s")
    print(f"{'outcome':>60} {'runs':>6}")
    for outcome, count in sorted(outcomes.items(), key=lambda item: -item[1]):
        print(f"{outcome[:60]:>60} {count:6d}")
    print()
    print("\n".join(notes))


if __name__ == "__main__":
    main(*(int(a) if a.isdigit() else a for a in sys.argv[1:4]))
