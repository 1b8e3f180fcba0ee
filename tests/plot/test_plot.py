import io

import numpy as np
import pytest

import terramesh as tm
from terramesh.errors import MeshValidityError
from terramesh.mesh.topology import signed_areas
from terramesh.plot import plot_mesh


def test_plot_writes_png(tmp_path):
    mesh = tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.2)
    path = tmp_path / "mesh.png"
    figure = plot_mesh(mesh, path)
    assert path.read_bytes()[:4] == b"\x89PNG"
    assert figure.axes[0].get_title().startswith(f"{mesh.n_points:,} vertices")
    import matplotlib.pyplot as plt

    plt.close(figure)


def test_plot_into_given_axes_without_colour():
    import matplotlib.pyplot as plt

    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]]))
    figure, ax = plt.subplots()
    assert plot_mesh(mesh, ax=ax, color_by=None, title="one") is figure
    assert ax.get_title() == "one"
    plt.close(figure)


def _triangle():
    return tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1]]), np.array([[0, 1, 2]]))


@pytest.mark.parametrize(
    "points, cells",
    [(np.zeros((0, 2)), np.zeros((0, 3), dtype=int)), (np.array([[0.0, 0], [1, 0], [0, 1]]), np.zeros((0, 3), int))],
    ids=["no points", "no cells"],
)
def test_plot_mesh_refuses_a_mesh_without_cells(points, cells):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match="at least one cell"):
        plot_mesh(tm.Mesh(points, cells))
    assert plt.get_fignums() == open_before


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_plot_mesh_refuses_non_finite_points(bad):
    with pytest.raises(MeshValidityError, match="NaN or infinite.*index 3"):
        tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1], [bad, 0]]), np.array([[0, 1, 2]]))
    mesh = tm.Mesh(np.array([[0.0, 0], [1, 0], [0, 1], [2, 0]]), np.array([[0, 1, 2]]))
    mesh.points[3, 0] = bad  # changed after the Mesh checked them: the plot checks again
    with pytest.raises(MeshValidityError, match="NaN or infinite.*index 3"):
        plot_mesh(mesh)


@pytest.mark.parametrize("color_by", ["qualty", "Quality", 1])
def test_plot_mesh_refuses_an_unknown_color_by(color_by):
    with pytest.raises(MeshValidityError, match="color_by"):
        plot_mesh(_triangle(), color_by=color_by)


@pytest.mark.parametrize("aspect", ["square", 0, -1.0, np.nan, np.inf, [1.0], True])
def test_plot_mesh_refuses_a_bad_aspect(aspect):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match="aspect"):
        plot_mesh(_triangle(), aspect=aspect)
    assert plt.get_fignums() == open_before


@pytest.mark.parametrize("aspect", ["equal", "auto", 2, np.float64(1.7)])
def test_plot_mesh_takes_the_aspects_matplotlib_takes(aspect):
    import matplotlib.pyplot as plt

    figure = plot_mesh(_triangle(), aspect=aspect)
    assert figure.axes[0].get_aspect() == (aspect if aspect != "equal" else 1.0)
    plt.close(figure)


def test_plot_mesh_refuses_a_3d_mesh_before_opening_a_figure():
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    tetrahedron = tm.Mesh(np.eye(4, 3), np.array([[0, 1, 2, 3]]))
    for color_by in ("quality", "resolution"):  # it said "points must have shape (n, 2)", or of the cells' shape
        with pytest.raises(
            MeshValidityError, match=r"plot_mesh draws 2D triangle meshes; this one's points have shape"
        ):
            plot_mesh(tetrahedron, color_by=color_by)
    assert plt.get_fignums() == open_before


def test_plot_mesh_refuses_a_missing_directory_before_drawing(tmp_path):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(FileNotFoundError, match="directory .*nowhere.* does not exist"):
        plot_mesh(_triangle(), tmp_path / "nowhere" / "mesh.png")
    assert plt.get_fignums() == open_before
    buffer = io.BytesIO()  # a file object is still matplotlib's to handle
    plt.close(plot_mesh(_triangle(), buffer))
    assert buffer.getvalue()[:4] == b"\x89PNG"


def _grid_mesh(nx, ny, width=1.0, height=1.0, origin=(0.0, 0.0), crs=None):
    """A structured mesh of 2 (nx - 1) (ny - 1) right triangles (q = 0.866) on a width by height box."""
    x, y = np.meshgrid(origin[0] + np.linspace(0.0, width, nx), origin[1] + np.linspace(0.0, height, ny), indexing="ij")
    index = np.arange(nx * ny).reshape(nx, ny)
    a, b, c, d = index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    return tm.Mesh(np.c_[x.ravel(), y.ravel()], np.concatenate([np.c_[a, b, c], np.c_[a, c, d]]), crs=crs)


def test_a_lonlat_mesh_is_drawn_at_its_ground_proportions_by_default():
    # aspect="equal" drew a degree of longitude at 55 N as long as a degree of latitude: squashed north-south
    import matplotlib.pyplot as plt

    from terramesh.plot._figures import figure_size

    lonlat = _grid_mesh(5, 5, 2.0, 2.0, origin=(10.0, 59.0), crs="EPSG:4326")
    figure = plot_mesh(lonlat)
    ax = figure.axes[0]
    assert ax.get_aspect() == pytest.approx(2.0)  # 1 / cos(60 degrees), the middle latitude
    assert tuple(figure.get_size_inches()) == figure_size(2.0, 2.0, 2.0, colorbar=True, labels=True)
    assert figure.get_size_inches()[1] > figure.get_size_inches()[0]  # 2 by 2 degrees: taller than wide
    plt.close(figure)
    planar = _grid_mesh(5, 5, 2.0, 2.0, origin=(10.0, 59.0))
    for mesh, options, expected in [(planar, {}, 1.0), (lonlat, {"aspect": "equal"}, 1.0), (lonlat, {"aspect": 3}, 3)]:
        figure = plot_mesh(mesh, **options)
        assert figure.axes[0].get_aspect() == expected
        plt.close(figure)


def test_axes_are_labelled_in_degrees_for_a_lonlat_mesh_else_x_and_y():
    import matplotlib.pyplot as plt

    for mesh, labels in [
        (_grid_mesh(3, 3, origin=(10.0, 55.0), crs="EPSG:4326"), ("longitude (°)", "latitude (°)")),
        (_grid_mesh(3, 3), ("x", "y")),  # the mesh carries no unit
    ]:
        for color_by in ("quality", None):
            figure = plot_mesh(mesh, color_by=color_by)
            assert (figure.axes[0].get_xlabel(), figure.axes[0].get_ylabel()) == labels
            plt.close(figure)


def test_poor_cells_are_drawn_red_below_the_colour_scale(squashed_mesh):
    # the scale was clipped at 0.5: a q = 0.17 cell had the colour of a q = 0.5 one, dark purple, no sign of it
    import matplotlib.colors
    import matplotlib.pyplot as plt

    mesh = squashed_mesh
    quality = tm.quality.triangle_quality(mesh.points, mesh.cells)
    poor = quality < 0.5
    assert poor.sum() == 20 and (quality > 0.5).sum() == 100
    figure = plot_mesh(mesh)
    figure.canvas.draw()
    ax = figure.axes[0]
    cells = ax.collections[0]
    faces = cells.get_facecolor()
    red = matplotlib.colors.to_rgba("red")
    assert np.allclose(faces[poor], red) and not np.isclose(faces[~poor], red).all(axis=1).any()
    assert (cells.norm.vmin, cells.norm.vmax) == (0.5, 1.0)  # the scale of good meshes, kept
    assert cells.colorbar.extend == "min" and np.allclose(cells.cmap.get_under(), red)
    assert ax.get_title().endswith(", 20 below 0.5 (red, circled)")
    # circled too: a poor cell is a pixel or two on a real mesh, its red not seen where the title counts it
    (markers,) = [line for line in ax.lines if line.get_gid() == "poor cells"]
    centroids = mesh.points[mesh.cells[poor]].mean(axis=1)
    assert np.allclose(markers.get_xydata(), centroids) and markers.get_markeredgecolor() == "red"
    plt.close(figure)
    figure = plot_mesh(_grid_mesh(3, 3))
    assert figure.axes[0].collections[0].colorbar.extend == "min"  # the same bar, with no poor cell
    assert figure.axes[0].get_title().endswith("mean q 0.866")
    assert not [line for line in figure.axes[0].lines if line.get_gid() == "poor cells"]
    plt.close(figure)


def test_a_large_mesh_has_one_colour_per_cell_and_its_poor_cells_red():
    # a large mesh's cells are drawn as Gouraud triangles on vertices of their own: the colours must stay flat
    import matplotlib
    import matplotlib.pyplot as plt

    thin = np.linspace(0.0, 0.5, 301)  # columns 1/600 wide beside rows 1/60 high: q = 0.12
    square = np.linspace(0.5, 1.0, 31)[1:]  # q = 0.866
    x, y = np.meshgrid(np.r_[thin, square], np.linspace(0.0, 1.0, 61), indexing="ij")
    index = np.arange(x.size).reshape(x.shape)
    a, b, c, d = index[:-1, :-1].ravel(), index[1:, :-1].ravel(), index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    mesh = tm.Mesh(np.c_[x.ravel(), y.ravel()], np.concatenate([np.c_[a, b, c], np.c_[a, c, d]]))
    assert mesh.n_cells > 20_000  # drawn as an image's triangles
    figure, ax = plt.subplots(figsize=(4.0, 4.0), dpi=100)
    plot_mesh(mesh, ax=ax, edges=False)  # the colours alone (the square cells are large enough for edges)
    figure.canvas.draw()
    pixels = np.asarray(figure.canvas.buffer_rgba())[:, :, :3].astype(int)
    height = pixels.shape[0]
    good = np.array(matplotlib.colormaps["viridis"]((0.866 - 0.5) / 0.5)[:3]) * 255
    for x_data, expected in [(0.25, (255, 0, 0)), (0.75, good)]:
        for y_data in (0.2, 0.5, 0.8):
            column, row = ax.transData.transform((x_data, y_data))
            colour = pixels[height - int(row), int(column)]
            assert np.abs(colour - expected).max() <= 2, (x_data, y_data, colour)
    plt.close(figure)


def test_edges_are_drawn_where_they_can_be_seen():
    # a 160k-vertex disk came out olive, the 318k-vertex coastal mesh black at the coasts: edges over every colour
    import matplotlib.pyplot as plt

    small, dense = _grid_mesh(6, 6), _grid_mesh(61, 61)  # 50 cells; 7,200 cells in 2 by 2 inches below
    figure = plot_mesh(small)
    assert len(figure.axes[0].lines) > 0
    plt.close(figure)
    for mesh, options, drawn in [
        (dense, {}, False),  # some 3,000 cells a square inch of picture
        (dense, {"edges": True}, True),
        (dense, {"color_by": None}, True),  # the edges are the picture
        (small, {"edges": False}, False),
    ]:
        figure, ax = plt.subplots(figsize=(2.0, 2.0))
        plot_mesh(mesh, ax=ax, **options)
        assert (len(ax.lines) > 0) == drawn, options
        assert len(ax.collections) == (0 if options.get("color_by", "quality") is None else 1)
        plt.close(figure)


def test_auto_edges_leave_the_fine_part_of_a_graded_mesh_to_its_colours():
    # a multiscale mesh's inner box, the area of interest, was drawn solid black: the whole mesh's density decided
    import matplotlib.pyplot as plt

    mesh = tm.generate_mesh(
        tm.geometry.Rectangle((0, 0), (1, 1)), lambda p: 0.006 + 0.25 * np.maximum(p[:, 0] - 0.3, 0.0), seed=0
    )
    figure, ax = plt.subplots(figsize=(3.0, 3.0))
    plot_mesh(mesh, ax=ax)
    x = np.concatenate([line.get_xdata() for line in ax.lines])
    x = x[np.isfinite(x)]
    assert len(x) > 100 and x.min() > 0.3  # edges where cells are large on the picture, none where fine
    plt.close(figure)


@pytest.mark.parametrize("options", [{"edges": "sometimes"}, {"edges": None}, {"edges": False, "color_by": None}])
def test_plot_mesh_refuses_edges_it_cannot_draw(options):
    import matplotlib.pyplot as plt

    open_before = plt.get_fignums()
    with pytest.raises(MeshValidityError, match="edges"):
        plot_mesh(_triangle(), **options)
    assert plt.get_fignums() == open_before


def test_a_large_mesh_is_rasterized_in_vector_output(tmp_path):
    # 319k cells as PDF triangles: 7 MB, 14 to 29 s
    import matplotlib.pyplot as plt

    large = _grid_mesh(105, 105)
    assert large.n_cells > 20_000
    figure = plot_mesh(large, tmp_path / "mesh.pdf", edges=True)
    ax = figure.axes[0]
    assert ax.collections[0].get_rasterized() and all(line.get_rasterized() for line in ax.lines)
    pdf = (tmp_path / "mesh.pdf").read_bytes()
    assert pdf[:4] == b"%PDF" and len(pdf) < 1_000_000
    plt.close(figure)
    figure = plot_mesh(_grid_mesh(6, 6))  # a small one stays vector: sharp at any zoom
    ax = figure.axes[0]
    assert not ax.collections[0].get_rasterized() and not any(line.get_rasterized() for line in ax.lines)
    plt.close(figure)


@pytest.mark.parametrize("shape", [(70.0, 13.0), (13.0, 70.0)], ids=["seismic section", "tall"])
def test_the_colour_bar_is_no_taller_than_the_picture(shape):
    # a 70 by 13 km section was drawn 1.5 inches tall beside a 2 inch colour bar
    import matplotlib.pyplot as plt

    figure = plot_mesh(_grid_mesh(15, 15, *shape))
    figure.canvas.draw()
    ax = figure.axes[0]
    picture, bar = ax.get_window_extent(), ax.collections[0].colorbar.ax.get_window_extent()
    assert picture.y0 - 1 <= bar.y0 and bar.y1 <= picture.y1 + 1  # pixels
    assert bar.height > 0.6 * picture.height and bar.x0 >= picture.x1  # and beside it, not a sliver
    assert figure.bbox.contains(bar.x1, bar.y1)
    plt.close(figure)


def test_a_mesh_coloured_by_its_depth_and_its_resolution(tmp_path):
    # the guide's plot types: only the quality (or nothing) could be drawn
    import matplotlib.pyplot as plt

    mesh = tm.generate_mesh(
        tm.geometry.Rectangle((10.0, 55.0), (10.4, 55.2)), lambda p: 0.01 + 0.1 * (p[:, 0] - 10.0), h0=0.01
    )
    mesh.crs = "EPSG:4326"
    mesh.point_data["depth"] = 5.0 + 100.0 * (mesh.points[:, 0] - 10.0)
    figure = plot_mesh(mesh, tmp_path / "depth.png", color_by="depth")
    shaded = figure.axes[0].collections[0]
    assert shaded.colorbar.ax.get_ylabel() == "depth (m, positive down)"
    assert np.allclose(shaded.get_clim(), [mesh.depth.min(), mesh.depth.max()])
    assert figure.axes[0].get_title() == f"depth (m, positive down): {mesh.depth.min():.3g} to {mesh.depth.max():.3g}"
    figure = plot_mesh(mesh, tmp_path / "resolution.png", color_by="resolution")
    shaded = figure.axes[0].collections[0]
    low, high = shaded.get_clim()
    # ground metres: 0.01 degree of longitude at 55 N is 640 m, of latitude 1,113 m
    assert 500 < low < 1000 and high > 3 * low and shaded.colorbar.ax.get_ylabel() == "mean edge length (m)"
    plt.close("all")
    with pytest.raises(MeshValidityError, match=r"color_by must be .* a point_data name \(depth\), got .salinity."):
        plot_mesh(mesh, color_by="salinity")
    mesh.point_data["depth"][3] = np.nan
    with pytest.raises(MeshValidityError, match=r"point_data\['depth'\] has 1 NaN or infinite values"):
        plot_mesh(mesh, color_by="depth")


def test_a_seismic_mesh_is_drawn_with_its_axes_and_units():
    # an (x, z) section in metres got axes "x" and "y" and a resolution in "mesh units"
    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, -1000), (3000, 0)), 250.0)
    figure = plot_mesh(mesh, color_by="resolution", units="m", axis_names=("x", "z"))
    ax = figure.axes[0]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (m)", "z (m)")
    assert ax.collections[0].colorbar.ax.get_ylabel() == "mean edge length (m)"
    plain = plot_mesh(mesh).axes[0]
    assert (plain.get_xlabel(), plain.get_ylabel()) == ("x", "y")


def test_auto_edges_outline_no_scattered_cells():
    # cell by cell, a seismic mesh got its few dozen largest cells outlined: black specks like flagged cells
    import matplotlib.pyplot as plt

    rng = np.random.default_rng(0)
    centres = rng.uniform(0.1, 0.9, (8, 2))

    def size(p):
        bumps = np.exp(-((p[:, None, :] - centres[None]) ** 2).sum(axis=2) / 0.03**2).sum(axis=1)
        return 0.012 + 0.03 * bumps  # fine everywhere, a few cells twice to three times as large at each bump

    mesh = tm.generate_mesh(tm.geometry.Rectangle((0, 0), (1, 1)), size, seed=0)
    figure, ax = plt.subplots(figsize=(3.0, 3.0))
    inches = np.prod(ax.get_position().size * figure.get_size_inches())
    areas = np.abs(signed_areas(mesh.points, mesh.cells))
    assert 0 < np.count_nonzero(areas * inches * 1000.0 > 1.0) < 0.05 * mesh.n_cells  # specks, cell by cell
    plot_mesh(mesh, ax=ax)
    assert not ax.lines  # no edges drawn: the colours alone
    plt.close(figure)


def test_depth_is_coloured_water_blue_and_land_apart_at_zero():
    # plain viridis over -100..+45 m: deep water bright yellow, dry ground dark purple, nothing at 0 m
    import matplotlib.pyplot as plt

    mesh = _grid_mesh(21, 11, 2.0, 1.0)
    mesh.point_data["depth"] = 45.0 - 72.5 * mesh.points[:, 0]  # 45 m deep in the west, 100 m high ground east
    figure = plot_mesh(mesh, color_by="depth")
    shaded = figure.axes[0].collections[0]
    assert shaded.norm(0.0) == pytest.approx(0.5)  # 0 m in the middle of the bar, where blue meets land
    assert shaded.colorbar.ax.get_ylabel() == "depth (m, positive down)"
    deep, shallow, shore, high = (np.asarray(shaded.cmap(shaded.norm(d)))[:3] for d in (45.0, 1.0, -1.0, -100.0))
    assert deep[2] > deep[0] + 0.3 and shallow[2] > shallow[0]  # water: blue, darker the deeper
    assert deep.sum() < shallow.sum()
    assert shore[1] > shore[2] and not np.allclose(shore, shallow, atol=0.2)  # dry ground: green, not blue
    assert not np.allclose(high, deep, atol=0.2)
    assert "mean q" not in figure.axes[0].get_title()
    figure.canvas.draw()
    pixels = np.asarray(figure.canvas.buffer_rgba())[:, :, :3].astype(int)
    ax = figure.axes[0]
    for x_data, water in [(0.1, True), (1.9, False)]:
        column, row = ax.transData.transform((x_data, 0.5))
        r, g, b = pixels[pixels.shape[0] - int(row), int(column)]
        assert (b > r + 40) == water, (x_data, r, g, b)
    plt.close(figure)
    wet = _grid_mesh(5, 5)
    wet.point_data["depth"] = 5.0 + 10.0 * wet.points[:, 0]  # all water: blues only, its own range
    shaded = plot_mesh(wet, color_by="depth").axes[0].collections[0]
    assert np.allclose(shaded.get_clim(), [5.0, 15.0])
    assert all(c[2] > c[0] for c in shaded.cmap(np.linspace(0.0, 1.0, 5)))
    plt.close("all")


def test_an_outlier_does_not_give_a_field_one_colour():
    # one vertex at 1e9 in a 1.5-4.8 km/s velocity field drew everything else the bar's lowest colour
    import matplotlib.pyplot as plt

    mesh = _grid_mesh(41, 11, 4.0, 1.0)
    velocity = 1500.0 + 800.0 * mesh.points[:, 0]
    mesh.point_data["velocity"] = velocity.copy()
    mesh.point_data["velocity"][7] = 1e9
    figure = plot_mesh(mesh, color_by="velocity")
    shaded = figure.axes[0].collections[0]
    low, high = shaded.get_clim()
    assert low == pytest.approx(1500.0) and 4000.0 < high <= 4700.0
    assert shaded.colorbar.extend == "max"  # the clipped end pointed
    assert figure.axes[0].get_title() == "velocity (m/s): 1,500 to 1e+09"  # the whole range, said
    plt.close(figure)
    mesh.point_data["velocity"] = velocity  # a smooth field keeps its whole range
    shaded = plot_mesh(mesh, color_by="velocity").axes[0].collections[0]
    assert np.allclose(shaded.get_clim(), [1500.0, 4700.0]) and shaded.colorbar.extend == "neither"
    plt.close("all")


def test_a_field_colour_bar_gives_its_units_or_the_label_asked_for():
    # velocity's bar said "velocity", no unit
    import matplotlib.pyplot as plt

    mesh = _grid_mesh(5, 5)
    mesh.point_data["velocity"] = 1500.0 + mesh.points[:, 0]
    mesh.point_data["salinity"] = 30.0 + mesh.points[:, 1]
    for options, expected in [
        ({"color_by": "velocity"}, "velocity (m/s)"),
        ({"color_by": "velocity", "label": "vp (m/s)"}, "vp (m/s)"),
        ({"color_by": "salinity"}, "salinity"),
        ({"color_by": "salinity", "label": "salinity (PSU)"}, "salinity (PSU)"),
        ({"color_by": "resolution", "label": "h (m)"}, "h (m)"),
    ]:
        ax = plot_mesh(mesh, **options).axes[0]
        assert ax.collections[0].colorbar.ax.get_ylabel() == expected
        assert ax.get_title().startswith(f"{expected}: ")  # the field and its range, not the quality
        plt.close("all")


def test_a_one_cell_mesh_is_counted_in_the_singular():
    import matplotlib.pyplot as plt

    figure = plot_mesh(_triangle())
    assert figure.axes[0].get_title() == "3 vertices, 1 cell, mean q 0.866"
    plt.close(figure)


def test_a_long_seismic_section_fills_its_figure():
    # a 67 by 12 km section was drawn between blank bands a third of the figure's height
    import matplotlib.pyplot as plt

    mesh = _grid_mesh(68, 13, 67_400.0, 11_900.0, origin=(0.0, -11_900.0))
    figure = plot_mesh(mesh, color_by="resolution", units="m", axis_names=("x", "z"))
    figure.canvas.draw()
    ax = figure.axes[0]
    picture = ax.transData.transform([[0.0, -11_900.0], [67_400.0, 0.0]])
    picture_height = picture[1, 1] - picture[0, 1]
    blank = (figure.bbox.height - picture_height) / figure.dpi
    assert blank < 1.6  # inches above and below the picture: the title, ticks and x label (2.5 before)
    assert ax.get_window_extent().height < 1.15 * picture_height  # the axes hold the picture, little blank
    plt.close(figure)
