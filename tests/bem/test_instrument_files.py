"""Real instrument files (tests/data/instrument, SurfaceTopography's test data) read by bem.rough.read_surface:
the unit each file states, missing points, files too small, headers checked before any data is read.

The expected numbers come from SurfaceTopography's own reader of the same file (its raw heights and sizes,
in the file's unit) times the metres of the unit the file states, a table written here.
"""

import logging
import re

import numpy as np
import pytest
from scipy import ndimage

import bem
from bem import rough

from ..instrument_data import instrument_file, rewrite_x3p, write_x3p

st = pytest.importorskip("SurfaceTopography")

METRES = {"m": 1.0, "mm": 1e-3, "nm": 1e-9}


def _raw(path):
    """SurfaceTopography's heights (masked), sizes and unit of a file, as stated."""
    reader = st.open_topography(str(path))
    topo = reader.topography()
    return topo.heights(), tuple(topo.physical_sizes), reader.default_channel.unit


@pytest.mark.parametrize("name, unit, size", [
    ("sur-2.sur", "mm", (1.9614921, 1.6862561)),   # Digital Surf, 563 x 484, with 117 missing points
    ("top-1.top", "nm", (600.0, 600.0)),           # 256 x 256
    ("matrix-4.txt", "m", (2.773965e-05, 1.1280791e-04)),  # a Gwyddion text export, 75 x 305
])
def test_a_file_comes_back_in_metres_by_the_unit_it_states(tmp_path, name, unit, size):
    path = instrument_file(name, tmp_path)
    raw, raw_size, raw_unit = _raw(path)
    assert raw_unit == unit and raw_size == pytest.approx(size, rel=1e-7)  # the file, as its README says
    s = rough.read_surface(path, detrend=None, fill="harmonic")
    m = METRES[unit]
    assert (s.stats.unit, s.stats.length_unit) == (unit, "m")
    assert s.size == pytest.approx((size[0] * m, size[1] * m), rel=1e-7)
    measured = ~np.ma.getmaskarray(raw)
    assert np.allclose(s.heights[measured], np.ma.getdata(raw)[measured] * m, rtol=1e-12, atol=0)
    assert s.stats.rms_height == pytest.approx(np.std(s.heights), rel=1e-9)


def test_a_unit_given_for_a_file_that_states_another_is_refused(tmp_path):
    path = instrument_file("top-1.top", tmp_path)
    with pytest.raises(bem.InputError, match=r"^unit = 'um' is not allowed: .* states its lengths in nm"):
        rough.read_surface(path, unit="um")
    agreeing = [rough.read_surface(path, unit=u, detrend=None) for u in ("nm", 1e-9)]
    assert agreeing[0].size == agreeing[1].size == pytest.approx((6e-7, 6e-7), rel=1e-12)
    in_um = rough.read_surface(path, length_unit="um", detrend=None)
    assert in_um.size == pytest.approx((0.6, 0.6), rel=1e-12)
    assert np.allclose(in_um.heights, agreeing[0].heights * 1e6, rtol=1e-12, atol=0)


def test_a_file_that_states_no_unit_needs_one(tmp_path):
    path = instrument_file("ibw-10x10.ibw", tmp_path)
    raw, raw_size, raw_unit = _raw(path)
    assert raw_unit is None
    with pytest.raises(bem.InputError, match=r"^unit is missing: .*ibw-10x10.ibw' states no length unit"):
        rough.read_surface(path)
    s = rough.read_surface(path, unit="um", detrend=None)
    assert s.size == pytest.approx((raw_size[0] * 1e-6, raw_size[1] * 1e-6), rel=1e-12)
    assert np.allclose(s.heights, np.asarray(raw) * 1e-6, rtol=1e-12, atol=0) and s.stats.unit == "um"


def test_a_few_missing_points_are_filled_on_request_and_counted(tmp_path):
    path = instrument_file("sur-2.sur", tmp_path)
    raw, _, _ = _raw(path)
    holes = np.ma.getmaskarray(raw)
    assert holes.sum() == 117  # 0.043 % of the 563 x 484 points
    with pytest.raises(bem.InputError, match=r"^file = .* 117 points without data \(0.0429 % of 272492\); fill"):
        rough.read_surface(path)
    s = rough.read_surface(path, fill="harmonic", detrend=None)
    assert (s.stats.filled, s.stats.fill) == (117, "harmonic") and np.isfinite(s.heights).all()
    z = np.asarray(s.heights)
    assert np.array_equal(z[~holes], np.ma.getdata(raw)[~holes] * 1e-3)  # the measured points are kept
    # harmonic values obey the maximum principle: each hole's values lie within the heights measured around it
    labels, n = ndimage.label(holes)
    for k in range(1, n + 1):
        hole = labels == k
        ring = ndimage.binary_dilation(hole) & ~holes
        assert z[ring].min() <= z[hole].min() and z[hole].max() <= z[ring].max()


def test_more_than_five_percent_missing_is_refused_even_with_fill(tmp_path):
    path = instrument_file("frt-2.frt", tmp_path)
    with pytest.raises(bem.InputError, match=r"12314 points without data \(27.4 % of 45000\), more than 5 %"):
        rough.read_surface(path, fill="harmonic")


def test_a_real_file_with_too_few_points_is_refused(tmp_path):
    with pytest.raises(bem.InputError, match=r"^file = .*sdf-1.sdf' is not allowed: it holds 7 x 4 points"):
        rough.read_surface(instrument_file("sdf-1.sdf", tmp_path))


# --- headers checked before the data is read ------------------------------------------------------------

@pytest.fixture
def no_reading(monkeypatch):
    """Fail the test if SurfaceTopography is asked to open a file."""
    def refuse(*args, **kwargs):
        raise AssertionError("the file was handed to a reader")

    monkeypatch.setattr(st, "open_topography", refuse)


def test_x3p_data_that_does_not_match_its_header_is_refused(tmp_path, no_reading):
    path = tmp_path / "patch.x3p"
    write_x3p(path)  # float64 data (DataType D)
    rewrite_x3p(path, main=lambda text: text.replace("<DataType>D</DataType>", "<DataType>I</DataType>"))
    with pytest.raises(bem.InputError, match=r"data does not match its header: .* 16 x 12 values of type I "
                                             r"\(384 bytes\), the data member holds 1536 bytes"):
        rough.read_surface(path)


def test_an_x3p_that_would_inflate_beyond_its_header_is_refused_before_inflating(tmp_path, no_reading):
    path = tmp_path / "bomb.x3p"
    write_x3p(path)
    rewrite_x3p(path, data=bytes(20 * 2**20))  # 20 MiB of zeros in a 20 kB archive, declared 16 x 12
    assert path.stat().st_size < 100_000
    with pytest.raises(bem.InputError, match=r"does not match its header: .* holds 20971520 bytes"):
        rough.read_surface(path)
    rewrite_x3p(path, main=lambda text: text.replace("<SizeX>16</SizeX>", "<SizeX>8000000</SizeX>"))
    largest = re.escape(f"{bem.checks.max_nodes('the surface grid'):.3g}")
    with pytest.raises(bem.InputError, match=r"declares 8000000 x 12 = 9.6e\+07 points, more than the " + largest):
        rough.read_surface(path)


def test_an_npy_header_of_too_many_points_is_refused_before_reading(tmp_path, no_reading):
    path = tmp_path / "huge.npy"
    with open(path, "wb") as f:  # the header of an 8192 x 8192 float64 array, and no data
        np.lib.format.write_array_header_1_0(f, {"descr": "<f8", "fortran_order": False, "shape": (8192, 8192)})
    with pytest.raises(bem.InputError, match=r"^file = .* declares 8192 x 8192 = 6.71e\+07 points"):
        rough.read_surface(path, physical_sizes=(1.0, 1.0), unit="m")


@pytest.mark.parametrize("suffix, reader", [(".x3p", "x3p"), (".sur", "sur"), (".mi", "mi")])
def test_random_bytes_are_not_a_readable_file_of_their_extension(tmp_path, suffix, reader):
    path = tmp_path / f"noise{suffix}"
    path.write_bytes(np.random.default_rng(1).bytes(5000))
    with pytest.raises(bem.InputError, match=f"is not a readable {reader} file") as err:
        rough.read_surface(path)
    assert "physical_sizes" not in str(err.value)


def test_the_default_lattice_follows_the_coarser_pixel(tmp_path, caplog):
    path = tmp_path / "long_pixels.x3p"
    write_x3p(path, grid=(40, 40), size=(1e-5, 2.5e-5))  # dy = 2.5 dx, as x3p-2 of SurfaceTopography's data
    with caplog.at_level(logging.ERROR):
        s = rough.read_surface(path)
    dx, dy = s.stats.pixel
    assert (dx, dy) == pytest.approx((2.5e-7, 6.25e-7), rel=1e-12)
    lattice = s.to_lattice()
    assert lattice.step == pytest.approx(dy, rel=0.01)  # not dx: that would put 116 rows where the data has 40
    assert lattice.n_rows * lattice.n_cols <= 1.16 * 40 * 40  # the rows of a square-pixel grid's lattice
    square = rough.read_surface(instrument_file("matrix-4.txt", tmp_path))
    assert square.default_n_cols() == 75  # square pixels: one node per point along x
