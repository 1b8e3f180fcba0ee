"""``terramesh coastal``: choosing the shoreline file's layer and the DEM's variable from the command line."""

import sys

import numpy as np
import pyogrio
import pytest
import shapely

import terramesh as tm
from terramesh.cli import main

BOX = ("0", "1", "0", "1")


def _geopackage(path, *layers):
    """A GeoPackage of ``(name, geometry, geometry type)`` layers, in that order."""
    for name, geometry, kind in layers:
        wkb = shapely.to_wkb(np.array([geometry], dtype=object))
        pyogrio.raw.write(path, wkb, [], [], geometry_type=kind, crs="EPSG:4326", layer=name)
    return path


def _two_layer_geopackage(path):
    """Stations (points) first, as GDAL lists them, then the land: the west half of the box."""
    return _geopackage(
        path, ("stations", shapely.Point(0.75, 0.5), "Point"), ("land", shapely.box(-1.0, -1.0, 0.5, 2.0), "Polygon")
    )


def _two_variable_netcdf(path):
    """A DEM of elevation ``elev_m`` (sea east of 0.5 degrees) beside its uncertainty ``sigma``."""
    import netCDF4

    lon, lat = np.linspace(-0.1, 1.1, 25), np.linspace(-0.1, 1.1, 25)
    elevation = np.broadcast_to(np.where(lon < 0.5, 10.0, -20.0), (lat.size, lon.size))
    with netCDF4.Dataset(path, "w") as out:
        out.createDimension("lat", lat.size)
        out.createDimension("lon", lon.size)
        out.createVariable("lat", "f8", ("lat",))[:] = lat
        out.createVariable("lon", "f8", ("lon",))[:] = lon
        out.createVariable("elev_m", "f4", ("lat", "lon"))[:] = elevation
        out.createVariable("sigma", "f4", ("lat", "lon"))[:] = np.full(elevation.shape, 0.5)
    return path, elevation


def test_coastal_chooses_the_geopackage_layer(tmp_path, capsys):
    # no --layer: pyogrio took the first layer (the stations), and the error that followed advised --open-water,
    # which meshes the whole box, land included, as water; the land is the file's one polygon layer
    path = _two_layer_geopackage(tmp_path / "coast.gpkg")
    arguments = ["coastal", "--bbox", *BOX, "--shoreline", str(path), "--min-el", "15000", "--max-el", "15000", "-q"]
    assert main([*arguments, "-o", str(tmp_path / "a.14")]) == 0
    mesh = tm.read_mesh(tmp_path / "a.14")
    assert tm.cleanup.mesh_problems(mesh) == []
    lon = mesh.points[:, 0]
    assert lon.min() == pytest.approx(0.5, abs=1e-6) and lon.max() == pytest.approx(1.0, abs=1e-6)  # water alone
    assert main([*arguments, "--layer", "land", "-o", str(tmp_path / "b.14")]) == 0
    assert tm.read_mesh(tmp_path / "b.14").n_points == mesh.n_points
    assert main([*arguments, "--layer", "1", "-o", str(tmp_path / "c.14")]) == 0  # by number, 0-based
    assert tm.read_mesh(tmp_path / "c.14").n_points == mesh.n_points
    capsys.readouterr()
    assert main(["coastal", "--bbox", *BOX, "--layer", "land", "--min-el", "15000", "--dem", str(path)]) == 1
    assert "error: --layer chooses the layer of a shoreline file: give --shoreline too" in capsys.readouterr().err


def test_coastal_layers_named_by_year(tmp_path, capsys):
    # --layer 2019 was taken as the 2020th layer, and the error blamed the file ("not a vector file, or corrupt?")
    path = _geopackage(
        tmp_path / "years.gpkg",
        ("2020", shapely.box(-1.0, -1.0, 0.5, 2.0), "Polygon"),
        ("2019", shapely.box(-1.0, -1.0, 0.3, 2.0), "Polygon"),
    )
    arguments = ["coastal", "--bbox", *BOX, "--shoreline", str(path), "--min-el", "15000", "--max-el", "15000", "-q"]
    assert main([*arguments, "-o", str(tmp_path / "a.14")]) == 1
    err = capsys.readouterr().err
    assert "has 2 polygon layers: 2020 (Polygon), 2019 (Polygon); choose the land's with --layer 2020" in err
    for layer, coast in (("2019", 0.3), ("2020", 0.5), ("0", 0.5)):
        assert main([*arguments, "--layer", layer, "-o", str(tmp_path / "b.14")]) == 0
        assert tm.read_mesh(tmp_path / "b.14").points[:, 0].min() == pytest.approx(coast, abs=1e-6)
    assert main([*arguments, "--layer", "2", "-o", str(tmp_path / "c.14")]) == 1
    assert "years.gpkg has no layer 2; choose one of its 2 layers by name or 0-based number" in capsys.readouterr().err


def test_coastal_chooses_the_dem_variable(tmp_path, capsys, monkeypatch):
    # "choose the elevation with variable=...", and the command line had no way to
    path, elevation = _two_variable_netcdf(tmp_path / "dem.nc")
    arguments = ["coastal", "--bbox", *BOX, "--dem", str(path), "--min-el", "15000", "--fs", "3"]
    arguments += ["-o", str(tmp_path / "a.14")]
    assert main(arguments) == 1
    err = capsys.readouterr().err
    assert "several 2-D variables on the (lat, lon) grid, ['elev_m', 'sigma']" in err
    assert "choose the elevation with --dem-variable NAME, one of them" in err
    given = []  # the DEM build is given
    monkeypatch.setattr(sys.modules["terramesh.cli.coastal"], "build", lambda *args, **kwargs: given.append(args[2]))
    main([*arguments, "--dem-variable", "elev_m"])
    assert given[-1].source == "dem.nc" and np.array_equal(given[-1].elevation, elevation.T)
    assert main([*arguments, "--dem-variable", "depth"]) == 1
    assert "no 2-D variable 'depth' on (lat, lon); found ['elev_m', 'sigma']" in capsys.readouterr().err
    no_dem = ["coastal", "--bbox", *BOX, "--dem-variable", "elev_m", "--min-el", "15000", "--shoreline", str(path)]
    assert main(no_dem) == 1
    assert "error: --dem-variable names the elevation variable of a DEM: give --dem too" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--fs", "0"], "--fs must be a positive finite number, got 0.0"),
        (["--dis", "-0.1"], "--dis must be a positive finite number, got -0.1"),
        (["--dis", "0.3", "--g", "0"], "--g must be a positive number (inf: no limit), got 0.0"),
        (["--dis", "0.3", "--dem", "DEM", "--wl", "0"], "--wl must be a positive finite number, got 0.0"),
        (["--dis", "0.3", "--dem", "DEM", "--slp", "-1"], "--slp must be a positive finite number, got -1.0"),
        (["--dis", "0.3", "--dem", "DEM", "--ch", "150"], "--ch must be a number from 0 to 100, got 150.0"),
        (
            ["--dis", "0.3", "--dem", "DEM", "--dt", "30", "--eta", "-3"],
            "--eta must be a positive finite number, got -3.0",
        ),
        (
            ["--dis", "0.3", "--dem", "DEM", "--thalwegs", "pts.mat"],
            "--thalwegs are the channel function's (--ch): give --ch, its percentile, too",
        ),
        (
            ["--dis", "0.3", "--dem", "DEM", "--fl", "1000", "5000"],
            "--fl filter the bathymetry of the slope function: give --slp or --ch",
        ),
        ([], "no size function was asked for (--dis, --fs, --wl, --slp, --ch) and --max-el is unbounded"),
        # the fort.13 was written over the mesh, or over the DEM
        (["--dis", "0.3", "--dem", "DEM", "--fort13", "OUT"], "-o and --fort13 are both"),
        (["--dis", "0.3", "--dem", "DEM", "--fort13", "DEM"], "--fort13 would overwrite the --dem input"),
    ],
)
def test_coastal_size_errors_name_the_flags_typed(tmp_path, capsys, options, message):
    # the size functions' own names reached the command line: "elements_per_feature must be ...", "rate", "grade",
    # "percentile"; and "give channels (ch)" for --thalwegs without --ch
    shoreline = _two_layer_geopackage(tmp_path / "coast.gpkg")
    dem, _ = _two_variable_netcdf(tmp_path / "dem.nc")
    options = [
        str(dem) if option == "DEM" else str(tmp_path / "a.14") if option == "OUT" else option for option in options
    ]
    if "--dem" in options:
        options += ["--dem-variable", "elev_m"]
    arguments = ["coastal", "--bbox", *BOX, "--shoreline", str(shoreline), "--layer", "land", "--min-el", "15000"]
    assert main([*arguments, *options, "-q", "-o", str(tmp_path / "a.14")]) == 1
    err = capsys.readouterr().err
    assert f"terramesh coastal: error: {message}" in err
    assert "elements_per" not in err and "(ch)" not in err


def _utm_shapefile_without_crs(path):
    """The west half of the box (lon < 0.5) as land, in UTM zone 31N metres, in a shapefile without its .prj."""
    import pyproj

    land = shapely.segmentize(shapely.box(-1.0, -1.0, 0.5, 2.0), 0.01)
    to_utm = pyproj.Transformer.from_crs("EPSG:4326", "EPSG:32631", always_xy=True)
    land = shapely.transform(land, lambda lonlat: np.column_stack(to_utm.transform(*lonlat.T)))
    with pytest.warns(UserWarning, match="'crs' was not provided"):
        pyogrio.raw.write(path, shapely.to_wkb(np.array([land], dtype=object)), [], [], geometry_type="Polygon")
    assert not path.with_suffix(".prj").exists()
    return path


def test_coastal_takes_the_shorelines_crs(tmp_path, capsys):
    # a shapefile in UTM without its .prj: "pass crs=...", which the command line had no flag for
    path = _utm_shapefile_without_crs(tmp_path / "coast_utm.shp")
    arguments = ["coastal", "--bbox", *BOX, "--shoreline", str(path), "--min-el", "15000", "--max-el", "15000", "-q"]
    assert main([*arguments, "-o", str(tmp_path / "a.14")]) == 1
    err = capsys.readouterr().err
    assert "are not degrees: pass --crs ... (its projection, e.g. 'EPSG:32619' for UTM zone 19N)" in err
    assert "crs=" not in err
    assert main([*arguments, "--crs", "EPSG:32631", "-o", str(tmp_path / "a.14")]) == 0
    mesh = tm.read_mesh(tmp_path / "a.14")
    assert tm.cleanup.mesh_problems(mesh) == []
    lon = mesh.points[:, 0]
    assert lon.min() == pytest.approx(0.5, abs=1e-3) and lon.max() == pytest.approx(1.0, abs=1e-6)  # water alone
    assert main(["coastal", "--bbox", *BOX, "--crs", "EPSG:32631", "--min-el", "15000"]) == 1
    assert "error: --crs gives the CRS of a shoreline file: give --shoreline too" in capsys.readouterr().err
