"""terramesh.seismic.model: VelocityModel, and the unit and value checks every reader shares."""

import warnings

import numpy as np
import pytest

from terramesh.errors import SizingError, TerrameshWarning
from terramesh.seismic import VelocityModel, read_velocity
from terramesh.seismic.model import MAX_VELOCITY

from .test_segy import VOLUME
from .test_segy_surveys import NX, NZ, SECTION, write_line
from .test_velocity import SECTION_ZX, check_section


def test_model_does_not_share_memory_with_input():
    values = SECTION_ZX.T[:, ::-1].copy()
    model = VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0 - 10))
    values[:] = 1.0
    assert model.vmin == 1500.0


def test_km_per_s_is_converted_and_detected():
    model = read_velocity(SECTION_ZX / 1000, spacing=(10.0, 5.0), axis_order="zx", units="km/s")
    check_section(model)
    with pytest.warns(TerrameshWarning, match="looks like km/s"):
        read_velocity(SECTION_ZX / 1000, spacing=(10.0, 5.0), axis_order="zx")
    # m/s given as km/s only warned, and went on as a model of 1,500,000 m/s and more
    with pytest.raises(SizingError, match=r"3\.03e\+06 m/s \(given as 3030 km/s\).*look like m/s.*units='m/s'"):
        read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx", units="km/s")
    with pytest.raises(SizingError, match="units"):
        read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx", units="ft/s")


def test_velocities_faster_than_any_earth_material_are_refused(tmp_path):
    # V * 400 (600,000..1,212,000 m/s) was read as a model without a word
    with pytest.raises(SizingError, match=r"largest velocity is 1\.212e\+06 m/s, faster than any Earth material"):
        read_velocity(SECTION_ZX * 400, spacing=(10.0, 5.0), axis_order="zx")
    with pytest.raises(SizingError, match=r"25000 m/s .*at most 20000 m/s"):
        read_velocity(SECTION_ZX / 1000 * 25 / 3.03, spacing=(10.0, 5.0), axis_order="zx", units="km/s")
    path = tmp_path / "vel.bin"
    (SECTION_ZX * 10).astype("<f4").tofile(path)
    with pytest.raises(SizingError, match=r"30300 m/s.*dtype \(now 'float32'\) and byte_order \(now 'little'\)"):
        read_velocity(path, shape=(3, 4), axis_order="zx", spacing=1.0)
    fastest = SECTION_ZX * MAX_VELOCITY / SECTION_ZX.max()
    assert read_velocity(fastest, spacing=1.0, axis_order="zx").vmax == pytest.approx(MAX_VELOCITY)


@pytest.mark.parametrize(
    "bad, message",
    [(np.nan, "NaN or infinite"), (np.inf, "NaN or infinite"), (0.0, "zero or negative"), (-5.0, "zero or negative")],
)
def test_nan_and_non_positive_velocities_are_refused(bad, message):
    values = SECTION_ZX.copy()
    values[1, 2] = bad
    # the index is the user's, in the user's axis order: it was the model's (x first, z flipped), (2, 1) here
    with pytest.raises(SizingError, match=rf"{message}.* at index \(1, 2\) \(z, x\)"):
        read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")


def test_masked_velocities_are_missing_ones():
    # the mask was dropped: a placeholder of 1 under it became a velocity of 1 m/s
    values = np.ma.masked_array(SECTION_ZX.copy(), mask=np.zeros(SECTION_ZX.shape, dtype=bool))
    values[1, 2] = 1.0
    values[1, 2] = np.ma.masked
    with pytest.raises(SizingError, match=r"1 NaN or infinite velocities \(the first at index \(1, 2\) \(z, x\)\)"):
        read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")
    with pytest.raises(SizingError, match=r"1 NaN or infinite velocities \(the first at index \(2, 1\)\)"):
        VelocityModel(values.T, ([0.0, 10.0, 20.0, 30.0], [-10.0, -5.0, 0.0]))
    values.mask = False  # unmasked: taken as it is, and 1 m/s beside 3030 m/s is refused as such
    with pytest.raises(
        SizingError, match=r"1 velocities below 100 m/s \(the first, 1 m/s, at index \(1, 2\) \(z, x\)\)"
    ):
        read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")


def test_a_bad_sample_is_named_at_its_index_in_the_file(tmp_path):
    import netCDF4

    values = np.transpose(np.broadcast_to(SECTION_ZX, (2, 3, 4)), (1, 2, 0)).copy()  # z, x, y
    values[2, 1, 0] = 0.0
    path = tmp_path / "cube.bin"
    values.astype("<f4").tofile(path)
    with pytest.raises(SizingError, match=r"at index \(2, 1, 0\) \(z, x, y\)"):
        read_velocity(path, shape=values.shape, axis_order="zxy", spacing=10.0)
    path = tmp_path / "cube.nc"
    with netCDF4.Dataset(path, "w") as ds:
        for name, size in zip("zxy", values.shape, strict=True):
            ds.createDimension(name, size)
        ds.createVariable("vp", "f4", ("z", "x", "y"))[:] = values
    with pytest.raises(SizingError, match=r"at index \(2, 1, 0\) \(z, x, y\)"):
        read_velocity(path, spacing=10.0)


def test_a_top_first_z_axis_is_named_z_with_the_order_expected():
    # a z axis of 0, -5, -10 was refused as "grid axis y must be strictly increasing"
    values = SECTION_ZX.T[:, ::-1]
    with pytest.raises(
        SizingError, match=r"grid axis z decreases \(0, -5, -10\); it must increase upward, bottom first"
    ):
        VelocityModel(values, (np.arange(4) * 10.0, -np.arange(3) * 5.0))
    with pytest.raises(SizingError, match=r"grid axis x decreases \(30, 20, 10, \.\.\.\); it must increase"):
        VelocityModel(values, (np.arange(4)[::-1] * 10.0, np.arange(3) * 5.0 - 10))
    with pytest.raises(SizingError, match="grid axis z must be evenly spaced"):
        VelocityModel(values, (np.arange(4) * 10.0, [-10.0, -4.0, 0.0]))
    with pytest.raises(SizingError, match=r"grid axis z decreases .* bottom first"):
        VelocityModel(VOLUME, (np.arange(4) * 25.0, np.arange(3) * 50.0, -np.arange(5) * 5.0))
    with pytest.raises(SizingError, match=r"grid axis y decreases"):
        VelocityModel(VOLUME, (np.arange(4) * 25.0, -np.arange(3) * 50.0, np.arange(5) * 5.0 - 20.0))


def test_a_z_axis_of_depths_positive_down_warns():
    # (x, z_depth) from 0 to 11,900 m was taken silently: the model upside down, above the free surface
    values = SECTION_ZX.T[:, ::-1]
    with pytest.warns(TerrameshWarning, match=r"its z axis runs 0\.\.10 m, all at or above 0, and z is the elevation"):
        VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0 - 10.0))  # the top at 0
        VelocityModel(values, (np.arange(4) * 10.0, np.arange(3) * 5.0 - 5.0))  # topography above the datum
        model = read_velocity(SECTION_ZX, spacing=5.0, axis_order="zx")
        again = read_velocity(model.values[..., ::-1], spacing=model.spacing, axis_order="xz")  # as documented
    np.testing.assert_array_equal(again.values, model.values)


@pytest.mark.parametrize("imaginary", [0.0, 30.0])
def test_complex_velocities_are_refused(tmp_path, imaginary):
    # a complex .npy drew NumPy's ComplexWarning and was read as its real part
    path = tmp_path / "vel.npy"
    values = SECTION_ZX + 0j
    values[1, 2] += 1j * imaginary
    np.save(path, values)
    parts = r"1 of 12 with a nonzero imaginary part" if imaginary else "imaginary parts all 0"
    message = rf"holds complex numbers \({parts}\): velocities are real numbers.* values\.real"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way
        with pytest.raises(SizingError, match=r"vel\.npy " + message):
            read_velocity(path, spacing=(10.0, 5.0), axis_order="zx")
        with pytest.raises(SizingError, match="the velocity array " + message):
            read_velocity(values, spacing=(10.0, 5.0), axis_order="zx")
        with pytest.raises(SizingError, match="the velocity model " + message):
            VelocityModel(values.T, ([0.0, 10.0, 20.0, 30.0], [-10.0, -5.0, 0.0]))


def test_repr_and_domain():
    model = read_velocity(SECTION_ZX, spacing=(10.0, 5.0), axis_order="zx")
    assert "4 x 3 nodes" in repr(model) and "1500..3030 m/s" in repr(model)
    np.testing.assert_allclose(model.domain.bbox, model.bbox)
    np.testing.assert_allclose(model.interior_bbox, model.bbox)
    volume = VelocityModel(VOLUME, (np.arange(4) * 25.0, np.arange(3) * 50.0, np.arange(5) * 5.0 - 20.0))
    assert "4 x 3 x 5 nodes, 75 x 100 x 20 m" in repr(volume)
    assert volume.domain.dim == 3
    np.testing.assert_allclose(volume.domain.bbox, volume.bbox)


def test_km_per_s_among_m_per_s_is_refused_with_count_and_place(tmp_path):
    # 1.5 km/s left among m/s values: a model of 1.5..4500 m/s, meshed 1000 times too finely there
    section = SECTION.copy()
    section[3:5, :4] /= 1000.0
    path = tmp_path / "mixed.segy"
    write_line(path, section, xs=np.arange(NX) * 12.5, scalar=-10)
    message = r"has 8 velocities below 100 m/s \(the first, 1\.53 m/s, at index \(3, 0\) \(trace, sample\)\) in a model"
    with pytest.raises(SizingError, match=message + r" reaching 2270 m/s: no rock or fluid is that slow"):
        read_velocity(path)
    with pytest.raises(SizingError, match=r"8 velocities below 100 m/s .* at index \(0, 3\) \(z, x\)"):
        read_velocity(section.T, spacing=10.0, axis_order="zx")
    with pytest.raises(SizingError, match="8 velocities below 100 m/s"):
        VelocityModel(section, (np.arange(NX) * 10.0, np.arange(NZ) * 10.0 - 290.0))
    with pytest.raises(SizingError, match=r"the first, 90 m/s"):  # given in km/s: judged in m/s
        read_velocity(np.array([[0.09, 2.0], [2.0, 2.0]]), spacing=10.0, axis_order="zx", units="km/s")
    slow = np.full((3, 3), 300.0)
    slow[1, 1] = 50.0  # a slow model (all below 1000 m/s) is left alone
    assert read_velocity(slow, spacing=10.0, axis_order="zx").vmin == 50.0


def test_velocity_values_of_another_shape_than_the_axes_are_named_as_velocities():
    # the interpolant's grid said "size values have shape (4, 3), the grid axes need (3, 3)"
    with pytest.raises(SizingError, match=r"velocity values have shape \(4, 3\), the axes \(x, z\) need \(3, 3\)"):
        VelocityModel(np.full((4, 3), 1500.0), ([0.0, 10.0, 20.0], [-10.0, -5.0, 0.0]))
