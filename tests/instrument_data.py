"""The real instrument files of tests/data/instrument (SurfaceTopography's test data, MIT; see its README)."""

import lzma
import shutil
import zipfile
from pathlib import Path

import numpy as np

FOLDER = Path(__file__).parent / "data" / "instrument"


def instrument_file(name, folder):
    """Copy the file ``name`` into ``folder`` (decompressing a stored ``name.xz``); returns its path."""
    target = Path(folder) / name
    packed = FOLDER / f"{name}.xz"
    if packed.is_file():
        with lzma.open(packed) as src, open(target, "wb") as dst:
            shutil.copyfileobj(src, dst)
    else:
        shutil.copyfile(FOLDER / name, target)
    return target


def unpacked(name):
    """The path of the instrument file ``name``, decompressed once per test run into a temporary folder."""
    import tempfile

    target = Path(tempfile.gettempdir()) / "contactlab-test-data" / name
    if not target.is_file():
        target.parent.mkdir(parents=True, exist_ok=True)
        instrument_file(name, target.parent)
    return target


def write_x3p(path, grid=(16, 12), size=(1e-5, 2.5e-5), seed=0):
    """A random height map [m] written as an .x3p (float64 data) by SurfaceTopography; returns the heights."""
    import SurfaceTopography as st

    z = np.random.default_rng(seed).normal(size=grid) * 1e-7
    st.Topography(z, size).to_x3p(str(path))
    return z


def rewrite_x3p(path, main=None, data=None):
    """Copy the x3p archive at ``path`` with its main.xml and data member replaced by ``main(text)`` and ``data``."""
    with zipfile.ZipFile(path) as zin:
        members = {i.filename: zin.read(i) for i in zin.infolist()}
    link = next(k for k in members if k != "main.xml" and not k.endswith("/") and "valid" not in k.lower())
    if main is not None:
        members["main.xml"] = main(members["main.xml"].decode()).encode()
    if data is not None:
        members[link] = data
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zout:
        for name, content in members.items():
            zout.writestr(name, content)
